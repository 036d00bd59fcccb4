// SPDX-License-Identifier: GPL-2.0-or-later
// A real WebSocket client (websocketpp) reaches rfbsim::Server's shared port the way noVNC does:
// HTTP upgrade to ws://HOST:PORT/websockify, then the whole RFB handshake and a first update over
// binary messages, while plain HTTP keeps working on the same port.
#include <catch2/catch.hpp>

#include <atomic>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "rfb_test_client.hpp"
#include "rfb_wire.hpp"
#include "rfbsim/server.hpp"
#include "served_scene.hpp"
#include "ws_test_client.hpp"

namespace {

using namespace std::chrono_literals;
using rfbsim::test::WsTestClient;

constexpr int kHandshakeWidth = 64;
constexpr int kHandshakeHeight = 48;

// A small gradient so that every pixel's value is known exactly.
std::vector<std::uint8_t> gradient_frame() {
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(kHandshakeWidth) * kHandshakeHeight * 4U);
  for (int y = 0; y < kHandshakeHeight; ++y) {
    for (int x = 0; x < kHandshakeWidth; ++x) {
      std::uint8_t* p = &pixels[(static_cast<std::size_t>(y) * kHandshakeWidth + static_cast<std::size_t>(x)) * 4U];
      p[0] = static_cast<std::uint8_t>(x * 4);
      p[1] = static_cast<std::uint8_t>(y * 5);
      p[2] = static_cast<std::uint8_t>(200 - x - y);
      p[3] = 255;
    }
  }
  return pixels;
}

}  // namespace

TEST_CASE("websocketpp client completes the RFB handshake over WebSocket and gets an update",
          "[robustness][websocket]") {
  // Record what the connect callback sees; it runs on the server's network thread.
  std::mutex seen_mutex;
  std::vector<rfbsim::ClientInfo> seen;
  rfbsim::ServerOptions options;
  options.width = kHandshakeWidth;
  options.height = kHandshakeHeight;
  options.desktop_name = "ws-handshake-test";
  options.json_routes["/ping.json"] = [] { return std::string(R"({"pong":42})"); };
  options.on_connect = [&](const rfbsim::ClientInfo& info) {
    std::lock_guard lock(seen_mutex);
    seen.push_back(info);
  };
  rfbsim::Server server(options);
  const auto frame = gradient_frame();
  server.submit(rfbsim::FrameView{frame.data(), kHandshakeWidth, kHandshakeHeight, 0});

  // The opening handshake must carry Origin (libvncserver refuses it otherwise).
  WsTestClient ws(server.port(), "/websockify", "http://127.0.0.1:" + std::to_string(server.port()), "binary");
  CHECK(ws.subprotocol() == "binary");
  const rfbsim::test::ReadExact read = [&ws](std::size_t n, std::vector<std::uint8_t>& out) {
    return ws.read_exact(n, out, 5s);
  };
  const rfbsim::test::WriteAll write = [&ws](const std::vector<std::uint8_t>& bytes) { return ws.send_binary(bytes); };

  // RFB handshake over binary messages; ServerInit must describe the server's options.
  const auto init = rfbsim::test::rfb_client_handshake(read, write);
  CHECK(init.width == kHandshakeWidth);
  CHECK(init.height == kHandshakeHeight);
  CHECK(init.name == "ws-handshake-test");
  CHECK(init.bits_per_pixel == 32);
  CHECK(init.true_colour);

  // The server counts the client once, as a WebSocket client.
  {
    std::lock_guard lock(seen_mutex);
    REQUIRE(seen.size() == 1);
    CHECK(seen[0].websocket);
    CHECK(seen[0].address == "127.0.0.1");
    CHECK(seen[0].id >= 1);
  }
  CHECK(server.client_count() == 1);
  CHECK(server.stats().clients == 1);

  // Plain HTTP on the same port answers while the WebSocket client is connected.
  const std::string response = rfbsim::test::http_get(server.port(), "/ping.json");
  CHECK(response.rfind("HTTP/1.1 200", 0) == 0);
  CHECK(rfbsim::test::http_body(response) == R"({"pong":42})");

  // Ask for Raw pixels of the whole frame: the update must carry exactly the submitted picture.
  REQUIRE(write(rfbsim::test::rfb_set_encodings({0})));
  REQUIRE(write(rfbsim::test::rfb_update_request(false, 0, 0, kHandshakeWidth, kHandshakeHeight)));
  const auto rects = rfbsim::test::rfb_read_raw_update(read, init.bits_per_pixel / 8);
  REQUIRE_FALSE(rects.empty());
  long covered = 0;
  int wrong_pixels = 0;
  for (const auto& rect : rects) {
    covered += static_cast<long>(rect.w) * rect.h;
    for (int y = 0; y < rect.h; ++y) {
      for (int x = 0; x < rect.w; ++x) {
        // The server's pixel format keeps red in the lowest byte: Raw bytes are R, G, B, X.
        const std::uint8_t* got = &rect.pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(rect.w) +
                                                static_cast<std::size_t>(x)) * 4U];
        const std::uint8_t* want = &frame[(static_cast<std::size_t>(rect.y + y) * kHandshakeWidth +
                                           static_cast<std::size_t>(rect.x + x)) * 4U];
        if (got[0] != want[0] || got[1] != want[1] || got[2] != want[2]) ++wrong_pixels;
      }
    }
  }
  CHECK(covered == static_cast<long>(kHandshakeWidth) * kHandshakeHeight);
  CHECK(wrong_pixels == 0);
  CHECK(ws.text_messages() == 0);
  // Counted once the server's write returns, which may be a moment after the client has read it all.
  CHECK(rfbsim::test::eventually([&] { return server.stats().updates_sent >= 1; }, 2s));

  // HTTP still answers after the update, and a close is noticed by the server.
  CHECK(rfbsim::test::http_body(rfbsim::test::http_get(server.port(), "/ping.json")) == R"({"pong":42})");
  ws.close();
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (server.client_count() != 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);  // the network thread notices the close on its next poll
  }
  CHECK(server.client_count() == 0);
}

TEST_CASE("a server that shuts down says so to WebSocket clients with a going-away close frame",
          "[robustness][websocket]") {
  rfbsim::ServerOptions options;
  options.width = kHandshakeWidth;
  options.height = kHandshakeHeight;
  auto server = std::make_unique<rfbsim::Server>(options);
  WsTestClient ws(server->port(), "/websockify", "http://127.0.0.1:" + std::to_string(server->port()), "binary");
  const rfbsim::test::ReadExact read = [&ws](std::size_t n, std::vector<std::uint8_t>& out) {
    return ws.read_exact(n, out, 5s);
  };
  const rfbsim::test::WriteAll write = [&ws](const std::vector<std::uint8_t>& bytes) { return ws.send_binary(bytes); };
  (void)rfbsim::test::rfb_client_handshake(read, write);
  REQUIRE(rfbsim::test::eventually([&] { return server->client_count() == 1; }, 2s));
  CHECK(ws.remote_close_code() == -1);

  server.reset();  // what SIGTERM does in sim_rfb
  REQUIRE(rfbsim::test::eventually([&] { return !ws.open(); }, 5s));
  // 1001: the page can tell "the simulation ended" from a network failure (1006, no close frame).
  CHECK(ws.remote_close_code() == 1001);
}
