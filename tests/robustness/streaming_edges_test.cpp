// SPDX-License-Identifier: GPL-2.0-or-later
// The edges of ContinuousUpdates and Fence, played byte by byte by hand-made clients while a
// well-behaved libvncclient client watches: a protocol error closes that one client, everything else is
// answered as rfbproto says, and the server keeps serving the others.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <vector>

#include "misbehaving_clients.hpp"
#include "raw_socket.hpp"
#include "rfb_wire.hpp"
#include "served_scene.hpp"

namespace {

using namespace std::chrono_literals;
using rfbsim::test::RawSocket;
using rfbsim::test::ServedScene;

constexpr std::int32_t kRaw = 0;
constexpr std::int32_t kFence = -312;
constexpr std::int32_t kContinuousUpdates = -313;

rfbsim::ServerOptions edges_server() {
  rfbsim::ServerOptions options;
  options.width = 160;
  options.height = 120;
  options.read_timeout = 500ms;
  return options;
}

std::vector<std::uint8_t> enable_continuous(bool enable, int x, int y, int w, int h) {
  std::vector<std::uint8_t> out{150, static_cast<std::uint8_t>(enable ? 1 : 0)};
  for (const int v : {x, y, w, h}) {
    out.push_back(static_cast<std::uint8_t>(v >> 8));
    out.push_back(static_cast<std::uint8_t>(v));
  }
  return out;
}

std::vector<std::uint8_t> fence(std::uint32_t flags, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> out(9 + payload.size());
  out[0] = 248;  // then 3 padding bytes
  for (int i = 0; i < 4; ++i) out[4 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(flags >> (24 - 8 * i));
  out[8] = static_cast<std::uint8_t>(payload.size());
  std::copy(payload.begin(), payload.end(), out.begin() + 9);
  return out;
}

// What the server sends a client that lists Fence and ContinuousUpdates: a ServerFence with only the
// Request bit and a one-byte payload (noVNC fails on a fence without Request), then EndOfContinuousUpdates.
void expect_announcement(RawSocket& socket) {
  std::vector<std::uint8_t> bytes;
  REQUIRE(socket.read_exact(10 + 1, bytes, 5s));
  CHECK(bytes[0] == 248);
  CHECK(bytes[4] == 0x80);  // Request, nothing else
  CHECK(bytes[5] == 0);
  CHECK(bytes[6] == 0);
  CHECK(bytes[7] == 0);
  CHECK(bytes[8] == 1);  // payload length
  CHECK(bytes[10] == 150);
}

// A client that did the handshake, listed Raw, Fence and ContinuousUpdates, and read the server's
// announcement.
rfbsim::test::RfbServerInit negotiate_streaming(RawSocket& socket) {
  const auto init = rfbsim::test::raw_rfb_handshake(socket);
  REQUIRE(socket.send_all(rfbsim::test::rfb_set_encodings({kRaw, kFence, kContinuousUpdates})));
  expect_announcement(socket);
  return init;
}

// The socket is closed by the server within `timeout`.
bool closed_by_server(RawSocket& socket, std::chrono::milliseconds timeout = 5s) {
  bool closed = false;
  socket.read_until_closed(timeout, &closed);
  return closed;
}

// A FramebufferUpdate in Raw arrives for a full request: the client is still served.
bool still_answers_requests(RawSocket& socket, const rfbsim::test::RfbServerInit& init) {
  const rfbsim::test::ReadExact read = [&](std::size_t n, std::vector<std::uint8_t>& out) {
    return socket.read_exact(n, out, 5s);
  };
  if (!socket.send_all(rfbsim::test::rfb_update_request(false, 0, 0, init.width, init.height))) return false;
  return !rfbsim::test::rfb_read_raw_update(read, init.bits_per_pixel / 8).empty();
}

}  // namespace

TEST_CASE("EnableContinuousUpdates without Fence closes only that client", "[robustness][streaming]") {
  ServedScene scene(edges_server());
  RawSocket socket(scene.port());
  const auto init = rfbsim::test::raw_rfb_handshake(socket);
  SECTION("ContinuousUpdates listed, Fence not") {
    REQUIRE(socket.send_all(rfbsim::test::rfb_set_encodings({kRaw, kContinuousUpdates})));
  }
  SECTION("neither listed") { REQUIRE(socket.send_all(rfbsim::test::rfb_set_encodings({kRaw}))); }
  REQUIRE(socket.send_all(enable_continuous(true, 0, 0, init.width, init.height)));
  CHECK(closed_by_server(socket));
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("EnableContinuousUpdates for an area outside the framebuffer closes only that client",
          "[robustness][streaming]") {
  ServedScene scene(edges_server());
  RawSocket socket(scene.port());
  const auto init = negotiate_streaming(socket);
  REQUIRE(socket.send_all(enable_continuous(true, 10, 0, init.width, init.height)));
  CHECK(closed_by_server(socket));
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("a fence payload over 64 bytes closes only that client", "[robustness][streaming]") {
  ServedScene scene(edges_server());
  RawSocket socket(scene.port());
  negotiate_streaming(socket);
  REQUIRE(socket.send_all(fence(1U << 31, std::vector<std::uint8_t>(65, 'x'))));
  CHECK(closed_by_server(socket));
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("a fence from a client that did not list Fence closes only that client", "[robustness][streaming]") {
  ServedScene scene(edges_server());
  RawSocket socket(scene.port());
  rfbsim::test::raw_rfb_handshake(socket);
  REQUIRE(socket.send_all(rfbsim::test::rfb_set_encodings({kRaw, kContinuousUpdates})));
  REQUIRE(socket.send_all(fence(1U << 31, {1})));
  CHECK(closed_by_server(socket));
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("truncated 150 and 248 messages are dropped after the read timeout", "[robustness][streaming]") {
  ServedScene scene(edges_server());
  RawSocket socket(scene.port());
  negotiate_streaming(socket);
  SECTION("EnableContinuousUpdates cut after 3 bytes") {
    REQUIRE(socket.send_all(std::vector<std::uint8_t>{150, 1, 0}));
  }
  SECTION("a fence cut inside its payload") {
    auto cut = fence(1U << 31, {1, 2, 3, 4, 5, 6, 7, 8});
    cut.resize(cut.size() - 4);
    REQUIRE(socket.send_all(cut));
  }
  CHECK(closed_by_server(socket));
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("a client's fence request is answered with Request, SyncNext and unknown bits cleared",
          "[robustness][streaming]") {
  ServedScene scene(edges_server());
  RawSocket socket(scene.port());
  const auto init = negotiate_streaming(socket);
  constexpr std::uint32_t kAsked = (1U << 31) | (1U << 2) | (1U << 0) | (1U << 20);  // Request SyncNext BlockBefore ?
  REQUIRE(socket.send_all(fence(kAsked, {'a', 'b', 'c'})));
  std::vector<std::uint8_t> answer;
  REQUIRE(socket.read_exact(9 + 3, answer, 5s));
  CHECK(answer == fence(1U << 0, {'a', 'b', 'c'}));
  CHECK(still_answers_requests(socket, init));
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("unasked fence answers are ignored and the client stays served", "[robustness][streaming]") {
  ServedScene scene(edges_server());
  RawSocket socket(scene.port());
  const auto init = negotiate_streaming(socket);
  // The first answers the server's announcement fence; the rest match nothing.
  for (int i = 0; i < 5; ++i) REQUIRE(socket.send_all(fence(0, {'p'})));
  CHECK(still_answers_requests(socket, init));
  CHECK(scene.server().client_count() == 2);
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("ContinuousUpdates push without requests, ping after each update, and end on disable",
          "[robustness][streaming]") {
  ServedScene scene(edges_server());
  RawSocket socket(scene.port());
  const auto init = rfbsim::test::raw_rfb_handshake(socket);
  const rfbsim::test::ReadExact read = [&](std::size_t n, std::vector<std::uint8_t>& out) {
    return socket.read_exact(n, out, 5s);
  };
  REQUIRE(socket.send_all(rfbsim::test::rfb_set_encodings({kRaw, kFence, kContinuousUpdates})));
  expect_announcement(socket);
  // Answer the announcement fence: congestion control has its first round trip.
  REQUIRE(socket.send_all(fence(0, {'p'})));
  // Enabled, the server pushes what it has not sent yet (the whole picture) without any request...
  REQUIRE(socket.send_all(enable_continuous(true, 0, 0, init.width, init.height)));
  const auto pushed = rfbsim::test::rfb_read_raw_update(read, init.bits_per_pixel / 8);
  CHECK_FALSE(pushed.empty());
  // ... and follows it with a ping: a fence with BlockBefore and Request, answered after the update.
  std::vector<std::uint8_t> ping;
  REQUIRE(socket.read_exact(10, ping, 5s));
  CHECK(ping[0] == 248);
  CHECK(ping[4] == 0x80);
  CHECK(ping[7] == 0x01);
  REQUIRE(socket.send_all(fence(0, {ping[9]})));
  // Disabled, the server confirms with EndOfContinuousUpdates, and requests are answered again.
  REQUIRE(socket.send_all(enable_continuous(false, 0, 0, 0, 0)));
  std::vector<std::uint8_t> confirm;
  REQUIRE(socket.read_exact(1, confirm, 5s));
  CHECK(confirm[0] == 150);
  CHECK(still_answers_requests(socket, init));
  socket.close();
  scene.check_still_serving();
}
