// SPDX-License-Identifier: GPL-2.0-or-later
// Bad clients against an in-process rfbsim::Server while a well-behaved libvncclient client watches.
// After each bad client the server must still (1) send the good client fresh frames, (2) accept and
// serve a new client, and (3) have forgotten the bad client. A peer's bad bytes close that one
// connection and nothing else.
#include <catch2/catch.hpp>

#include <poll.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>
#include <vector>

#include "misbehaving_clients.hpp"
#include "rfb_test_client.hpp"
#include "served_scene.hpp"

namespace {

using namespace std::chrono_literals;
using rfbsim::test::Clock;
using rfbsim::test::eventually;
using rfbsim::test::RawSocket;
using rfbsim::test::ServedScene;

rfbsim::ServerOptions bad_input_server() {
  rfbsim::ServerOptions options;
  options.width = 160;
  options.height = 120;
  return options;
}

// The status line of an HTTP response ("" when there is none).
std::string status_line(const std::string& response) { return response.substr(0, response.find("\r\n")); }

// Sends `request` on a new connection and returns everything received until the server closes it.
std::string http_exchange(int port, std::string_view request) {
  RawSocket socket(port);
  socket.send_all(request);
  return socket.read_until_closed(10s);
}

// Whether bytes (or EOF) are ready on the socket right now.
bool readable_now(const RawSocket& socket) {
  pollfd pfd{socket.fd(), POLLIN, 0};
  return ::poll(&pfd, 1, 0) > 0;
}

}  // namespace

TEST_CASE("garbage instead of the RFB version closes only that connection", "[robustness][rfb]") {
  struct Garbage {
    const char* what;
    std::string bytes;
  };
  std::string random = rfbsim::test::random_bytes(256, 7);
  random[0] = 'Z';  // not the start of an HTTP method, so it goes to the RFB side
  const std::vector<Garbage> cases = {
      {"random bytes", random},
      {"a long line without a newline", std::string(8000, 'A')},
      {"a TLS ClientHello-like start (0x16)",
       "\x16\x03\x01\x00\xa5\x01\x00\x00\xa1\x03\x03" + rfbsim::test::random_bytes(160, 11)},
      {"an SSLv2-like start (0x80)", "\x80\x2e\x01\x00\x02" + rfbsim::test::random_bytes(64, 13)},
      {"'RFB ' then junk", "RFB 999.999\n" + rfbsim::test::random_bytes(64, 17)},
  };
  // One server for all the cases (each check below runs after every bad client).
  ServedScene scene(bad_input_server());
  for (const auto& garbage : cases) {
    // Sent at once, libvncserver's first-bytes check sees it; sent after the greeting, its version parser.
    for (const bool after_greeting : {false, true}) {
      INFO(garbage.what << (after_greeting ? ", sent after the greeting" : ", sent at once"));
      RawSocket socket(scene.port());
      if (after_greeting) {
        std::vector<std::uint8_t> greeting;
        REQUIRE(socket.read_exact(12, greeting, 5s));
        REQUIRE(eventually([&] { return scene.server().client_count() == 2; }, 5s));
      }
      socket.send_all(garbage.bytes);  // may fail part-way once the server has closed on us
      bool closed = false;
      socket.read_until_closed(10s, &closed);
      CHECK(closed);
      socket.close();
      scene.check_still_serving();
    }
  }
}

TEST_CASE("a truncated RFB handshake is forgotten", "[robustness][rfb]") {
  rfbsim::ServerOptions options = bad_input_server();
  options.read_timeout = 1000ms;  // bounds how long a half-sent message may keep the server waiting
  ServedScene scene(options);
  SECTION("half a version at once, then close") {
    RawSocket socket(scene.port());
    REQUIRE(socket.send_all(std::string_view("RFB 003")));
    // Adopted as RFB: the greeting proves the server took the connection before we leave.
    std::vector<std::uint8_t> greeting;
    CHECK(socket.read_exact(12, greeting, 5s));
    socket.close();
  }
  SECTION("after the greeting, half a version, then close") {
    RawSocket socket(scene.port());
    std::vector<std::uint8_t> greeting;
    REQUIRE(socket.read_exact(12, greeting, 5s));
    REQUIRE(socket.send_all(std::string_view("RFB 00")));
    socket.close();
  }
  SECTION("half a version, then silence: the server gives up on its own") {
    RawSocket socket(scene.port());
    std::vector<std::uint8_t> greeting;
    REQUIRE(socket.read_exact(12, greeting, 5s));
    REQUIRE(socket.send_all(std::string_view("RFB 003.")));
    bool closed = false;
    socket.read_until_closed(15s, &closed);
    CHECK(closed);
  }
  SECTION("half a ServerInit exchange: security type chosen, then close") {
    RawSocket socket(scene.port());
    std::vector<std::uint8_t> bytes;
    REQUIRE(socket.read_exact(12, bytes, 5s));
    REQUIRE(socket.send_all(bytes));
    REQUIRE(socket.read_exact(2, bytes, 5s));  // one security type: None
    REQUIRE(socket.send_all(std::vector<std::uint8_t>{1}));
    socket.close();
  }
  scene.check_still_serving();
}

TEST_CASE("an oversized ClientCutText after a hand-made handshake closes only that client", "[robustness][rfb]") {
  ServedScene scene(bad_input_server());
  RawSocket socket(scene.port());
  const auto init = rfbsim::test::raw_rfb_handshake(socket);
  REQUIRE(init.width == 160);
  REQUIRE(scene.server().client_count() == 2);
  SECTION("length 0x7fffffff, then nothing") {
    REQUIRE(socket.send_all(rfbsim::test::rfb_client_cut_text_header(0x7fffffffU)));
  }
  SECTION("length 10 MB followed by a few bytes") {
    auto message = rfbsim::test::rfb_client_cut_text_header(10U * 1024U * 1024U);
    for (const char c : std::string_view("a few bytes of text")) message.push_back(static_cast<std::uint8_t>(c));
    REQUIRE(socket.send_all(message));
  }
  // The server refuses the length at once rather than waiting for (or allocating) the text.
  bool closed = false;
  socket.read_until_closed(10s, &closed);
  CHECK(closed);
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("bad WebSocket frames close only that connection", "[robustness][websocket]") {
  rfbsim::ServerOptions options = bad_input_server();
  options.read_timeout = 1000ms;
  ServedScene scene(options);
  RawSocket socket(scene.port());
  const std::string head = rfbsim::test::raw_websocket_upgrade(socket, scene.port());
  REQUIRE(head.rfind("HTTP/1.1 101", 0) == 0);
  CHECK(head.find("Sec-WebSocket-Protocol: binary\r\n") != std::string::npos);
  // The server counts the client just after it sends the 101 and the RFB greeting.
  REQUIRE(eventually([&] { return scene.server().client_count() == 2; }, 5s));
  const std::uint32_t mask = 0xa1b2c3d4U;
  // Twelve payload bytes that the server reads as the client's protocol version: not a valid one.
  const std::vector<std::uint8_t> junk_version(12, 'X');
  bool expect_server_close = true;

  SECTION("64-bit length 2^63-1") {
    auto frame = rfbsim::test::ws_header_claiming(0x7fffffffffffffffULL, mask);
    const auto payload = rfbsim::test::ws_mask(junk_version, mask);
    frame.insert(frame.end(), payload.begin(), payload.end());
    REQUIRE(socket.send_all(frame));
  }
  SECTION("64-bit length with the top bit set (2^64-1)") {
    auto frame = rfbsim::test::ws_header_claiming(0xffffffffffffffffULL, mask);
    const auto payload = rfbsim::test::ws_mask(junk_version, mask);
    frame.insert(frame.end(), payload.begin(), payload.end());
    REQUIRE(socket.send_all(frame));
  }
  SECTION("masked frame whose 16-bit length form carries a length under 126") {
    std::vector<std::uint8_t> frame{0x82, 0x80 | 126, 0x00, 0x0c, 0xa1, 0xb2, 0xc3, 0xd4};
    const auto payload = rfbsim::test::ws_mask(junk_version, mask);
    frame.insert(frame.end(), payload.begin(), payload.end());
    REQUIRE(socket.send_all(frame));
  }
  SECTION("masked frame claiming 100 bytes that sends 3 and closes") {
    std::vector<std::uint8_t> frame{0x82, 0x80 | 100, 0xa1, 0xb2, 0xc3, 0xd4, 0x11, 0x22, 0x33};
    REQUIRE(socket.send_all(frame));
    expect_server_close = false;  // the server waits for the rest; we leave instead
  }
  SECTION("unmasked client frame") {
    std::vector<std::uint8_t> frame{0x82, 12};
    frame.insert(frame.end(), junk_version.begin(), junk_version.end());
    REQUIRE(socket.send_all(frame));
  }
  if (expect_server_close) {
    bool closed = false;
    socket.read_until_closed(10s, &closed);
    CHECK(closed);
  }
  socket.close();
  scene.check_still_serving();
}

TEST_CASE("a WebSocket upgrade without Origin is refused", "[robustness][websocket]") {
  ServedScene scene(bad_input_server());
  RawSocket socket(scene.port());
  std::string request = rfbsim::test::ws_upgrade_request(scene.port(), "/websockify");
  const auto origin = request.find("Origin: ");
  request.erase(origin, request.find("\r\n", origin) + 2 - origin);
  REQUIRE(socket.send_all(request));
  bool closed = false;
  const std::string response = socket.read_until_closed(10s, &closed);
  CHECK(closed);
  CHECK(response.rfind("HTTP/1.1 101", 0) != 0);
  scene.check_still_serving();
}

TEST_CASE("a client that vanishes mid-update (reset) is dropped", "[robustness][rfb]") {
  rfbsim::ServerOptions options;
  options.width = 1280;
  options.height = 720;
  ServedScene scene(options);
  scene.submit_noise(1);
  REQUIRE(scene.good().wait_for_updates(1, 10s));
  // Four whole-frame Raw updates (3.7 MB each) cannot fit in the socket buffers: the server is still
  // writing when the reset arrives.
  CHECK(rfbsim::test::vanish_mid_update(scene.port(), 1280, 720, 4, 4096));
  scene.check_still_serving();
}

TEST_CASE("a client that stops reading is dropped and does not starve the others", "[robustness][rfb][busy]") {
  rfbsim::ServerOptions options;
  options.width = 640;
  options.height = 480;
  options.write_timeout = 1000ms;
  ServedScene scene(options);

  // The stalled client asks for many whole-frame Raw updates, then never reads again.
  RawSocket stalled(scene.port(), 16 * 1024);
  rfbsim::test::raw_rfb_handshake(stalled);
  REQUIRE(stalled.send_all(rfbsim::test::rfb_set_encodings({0})));
  for (int i = 0; i < 100; ++i) REQUIRE(stalled.send_all(rfbsim::test::rfb_update_request(false, 0, 0, 640, 480)));
  REQUIRE(scene.server().client_count() == 2);

  // Keep changing the picture: the good client keeps getting it, and the server drops the stalled one.
  int fresh_while_stalled = 0;
  const auto deadline = Clock::now() + 30s;
  while (scene.server().client_count() == 2 && Clock::now() < deadline) {
    if (scene.good_client_gets_fresh_frame(15s)) ++fresh_while_stalled;
  }
  CHECK(scene.server().client_count() == 1);
  CHECK(fresh_while_stalled >= 1);
  std::fprintf(stderr, "[robustness] stalled reader: %d fresh frames before it was dropped, longest wait %lld ms\n",
               fresh_while_stalled, static_cast<long long>(scene.longest_wait().count()));
  // The server closed the stalled connection (we still hold our end open).
  bool closed = false;
  stalled.read_until_closed(10s, &closed);
  CHECK(closed);
  scene.check_still_serving();
}

TEST_CASE("malformed HTTP gets the right status and leaves RFB alone", "[robustness][http][busy]") {
  // A web root, so that path checks (403) are reached.
  const auto root = std::filesystem::temp_directory_path() / ("rfbsim_robustness_" + std::to_string(::getpid()));
  std::filesystem::create_directories(root);
  std::ofstream(root / "index.html") << "<!doctype html><title>t</title>\n";
  rfbsim::ServerOptions options = bad_input_server();
  options.web_root = root.string();
  options.json_routes["/status.json"] = [] { return std::string(R"({"ok":1})"); };
  {
    ServedScene scene(options);
    const int port = scene.port();
    struct Exchange {
      const char* what;
      std::string request;
      const char* status;
    };
    const std::vector<Exchange> exchanges = {
        {"request line without a version", "GET /\r\n\r\n", "HTTP/1.1 400 Bad Request"},
        {"header line without ':'", "GET / HTTP/1.1\r\nHost 127.0.0.1\r\n\r\n", "HTTP/1.1 400 Bad Request"},
        {"a 20 kB header", "GET / HTTP/1.1\r\nX-Big: " + std::string(20 * 1024, 'b') + "\r\n\r\n",
         "HTTP/1.1 431 Request Header Fields Too Large"},
        {"a malformed percent escape", "GET /%zz HTTP/1.1\r\n\r\n", "HTTP/1.1 400 Bad Request"},
        {"a path that climbs out of the web root", "GET /../etc/passwd HTTP/1.1\r\n\r\n", "HTTP/1.1 403 Forbidden"},
        {"an escaped climb", "GET /a/%2e%2e/%2e%2e/etc/passwd HTTP/1.1\r\n\r\n", "HTTP/1.1 403 Forbidden"},
        {"a POST", "POST /status.json HTTP/1.1\r\nContent-Length: 2\r\n\r\n{}", "HTTP/1.1 405 Method Not Allowed"},
    };
    for (const auto& exchange : exchanges) {
      INFO(exchange.what);
      CHECK(status_line(http_exchange(port, exchange.request)) == exchange.status);
      CHECK(scene.good_client_gets_fresh_frame());
    }

    // One byte, then silence: answered 408 or closed at the HTTP timeout, and RFB is served meanwhile.
    RawSocket slow(port);
    REQUIRE(slow.send_all(std::string_view("G")));
    int fresh_meanwhile = 0;
    const auto deadline = Clock::now() + 20s;
    while (!readable_now(slow) && Clock::now() < deadline) {
      if (scene.good_client_gets_fresh_frame(2s)) ++fresh_meanwhile;
    }
    bool closed = false;
    const std::string response = slow.read_until_closed(5s, &closed);
    CHECK(closed);
    CHECK((status_line(response) == "HTTP/1.1 408 Request Timeout" || response.empty()));
    CHECK(fresh_meanwhile >= 3);

    // Well-formed requests still work, and so does RFB.
    const std::string ok = rfbsim::test::http_get(port, "/status.json");
    CHECK(status_line(ok) == "HTTP/1.1 200 OK");
    CHECK(rfbsim::test::http_body(ok) == R"({"ok":1})");
    scene.check_still_serving();
  }
  std::filesystem::remove_all(root);
}

TEST_CASE("HTTP connections beyond the worker pool wait for a worker instead of failing", "[robustness][http][waits]") {
  rfbsim::ServerOptions options = bad_input_server();
  options.json_routes["/status.json"] = [] { return std::string(R"({"ok":1})"); };
  ServedScene scene(options);
  const int port = scene.port();
  // More silent request heads than there are workers (16): each holds a worker until the HTTP timeout.
  std::vector<std::unique_ptr<RawSocket>> silent;
  for (int i = 0; i < 20; ++i) {
    silent.push_back(std::make_unique<RawSocket>(port));
    REQUIRE(silent.back()->send_all(std::string_view("G")));
  }
  std::this_thread::sleep_for(700ms);  // past the sniffing, so that all of them reach the HTTP workers
  // A browser's request arriving now waits for a free worker and is then answered, not refused with 503.
  const std::string answer = http_exchange(port, "GET /status.json HTTP/1.1\r\nHost: x\r\n\r\n");
  CHECK(status_line(answer) == "HTTP/1.1 200 OK");
  CHECK(rfbsim::test::http_body(answer) == R"({"ok":1})");
  scene.check_still_serving();
}
