// SPDX-License-Identifier: GPL-2.0-or-later
// A server behind a trusted relay (ServerOptions::proxy_protocol): the PROXY line's source address becomes
// the client's, a line marked view-only makes a watcher whose keys and pointer never reach the host, and a
// connection that does not begin with a valid line is closed without harm to the rest.
#include <catch2/catch.hpp>

#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "raw_socket.hpp"
#include "rfb_wire.hpp"
#include "rfbsim/server.hpp"

using rfbsim::test::RawSocket;
using namespace std::chrono_literals;

namespace {

struct ProxiedServer {
  std::mutex mutex;
  std::vector<std::string> addresses;
  std::vector<rfbsim::ClientInfo> infos;
  std::unique_ptr<rfbsim::Server> server;

  explicit ProxiedServer(bool with_http) {
    rfbsim::ServerOptions options;
    options.width = 64;
    options.height = 48;
    options.proxy_protocol = true;
    options.read_timeout = std::chrono::milliseconds(400);
    if (with_http) options.json_routes["/status.json"] = [] { return std::string("{}"); };
    options.on_connect = [this](const rfbsim::ClientInfo& client) {
      std::lock_guard lock(mutex);
      addresses.push_back(client.address);
      infos.push_back(client);
    };
    server = std::make_unique<rfbsim::Server>(std::move(options));
  }
  std::vector<std::string> seen() {
    std::lock_guard lock(mutex);
    return addresses;
  }
  std::vector<rfbsim::ClientInfo> clients() {
    std::lock_guard lock(mutex);
    return infos;
  }
  // libvncserver sends its greeting before it calls the new-client hook: wait for the hook a little.
  std::vector<std::string> seen_once_connected() {
    for (int i = 0; i < 500 && seen().empty(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return seen();
  }
};

// A raw RFB client behind `proxy_line`: the line, then the whole handshake (security None).
struct ProxiedClient {
  RawSocket socket;
  rfbsim::test::RfbServerInit init;

  ProxiedClient(int port, const std::string& proxy_line) : socket(port) {
    REQUIRE(socket.send_all(proxy_line));
    init = rfbsim::test::rfb_client_handshake(read(), write());
  }
  rfbsim::test::ReadExact read() {
    return [this](std::size_t n, std::vector<std::uint8_t>& out) { return socket.read_exact(n, out, 5s); };
  }
  rfbsim::test::WriteAll write() {
    return [this](const std::vector<std::uint8_t>& bytes) { return socket.send_all(bytes); };
  }
  // KeyEvent (message type 4): down flag, two bytes of padding, the keysym big-endian.
  bool send_key(std::uint32_t keysym, bool down) {
    return socket.send_all(std::vector<std::uint8_t>{4, static_cast<std::uint8_t>(down), 0, 0,
                                                     static_cast<std::uint8_t>(keysym >> 24),
                                                     static_cast<std::uint8_t>(keysym >> 16),
                                                     static_cast<std::uint8_t>(keysym >> 8),
                                                     static_cast<std::uint8_t>(keysym)});
  }
  // PointerEvent (message type 5): button mask, x and y big-endian.
  bool send_pointer(int x, int y, std::uint8_t buttons) {
    return socket.send_all(std::vector<std::uint8_t>{5, buttons, static_cast<std::uint8_t>(x >> 8),
                                                     static_cast<std::uint8_t>(x), static_cast<std::uint8_t>(y >> 8),
                                                     static_cast<std::uint8_t>(y)});
  }
  // A full update request answered: the server has read everything this client sent before it.
  bool round_trip() {
    if (!socket.send_all(rfbsim::test::rfb_update_request(false, 0, 0, init.width, init.height))) return false;
    return !rfbsim::test::rfb_read_raw_update(read(), init.bits_per_pixel / 8).empty();
  }
};

}  // namespace

TEST_CASE("behind a relay the PROXY line's source address is the client's, with or without HTTP on the port") {
  for (const bool with_http : {false, true}) {
    ProxiedServer proxied(with_http);
    RawSocket socket(proxied.server->port());
    REQUIRE(socket.send_all("PROXY TCP4 203.0.113.5 127.0.0.1 51234 5901\r\n"));
    // The server's RFB greeting follows: the line was consumed and the rest is RFB.
    CHECK(socket.read_until("\n", std::chrono::seconds(5)) == "RFB 003.008\n");
    const auto seen = proxied.seen_once_connected();
    REQUIRE(seen.size() == 1);
    CHECK(seen[0] == "203.0.113.5");
  }
}

TEST_CASE("a connection without a valid PROXY line is closed, and the next proxied one is served") {
  ProxiedServer proxied(false);
  {
    RawSocket garbage(proxied.server->port());
    REQUIRE(garbage.send_all("RFB 003.008\n"));
    bool closed = false;
    garbage.read_until_closed(std::chrono::seconds(5), &closed);
    CHECK(closed);
  }
  {
    RawSocket silent(proxied.server->port());  // says nothing: closed after read_timeout
    bool closed = false;
    silent.read_until_closed(std::chrono::seconds(5), &closed);
    CHECK(closed);
  }
  {
    RawSocket spoof(proxied.server->port());
    REQUIRE(spoof.send_all("PROXY TCP4 999.0.0.1 127.0.0.1 1 2\r\n"));
    bool closed = false;
    spoof.read_until_closed(std::chrono::seconds(5), &closed);
    CHECK(closed);
  }
  CHECK(proxied.seen().empty());
  RawSocket good(proxied.server->port());
  REQUIRE(good.send_all("PROXY TCP6 2001:db8::7 ::1 40000 5901\r\n"));
  CHECK(good.read_until("\n", std::chrono::seconds(5)) == "RFB 003.008\n");
  REQUIRE(proxied.seen_once_connected().size() == 1);
  CHECK(proxied.seen()[0] == "2001:db8::7");
}

TEST_CASE("a client behind \"PROXY UNKNOWN view-only\" is a watcher: it sees, its keys and pointer are dropped") {
  ProxiedServer proxied(false);
  ProxiedClient watcher(proxied.server->port(), "PROXY UNKNOWN view-only\r\n");
  CHECK(watcher.init.width == 64);
  REQUIRE(watcher.send_key('v', true));
  REQUIRE(watcher.send_key('v', false));
  REQUIRE(watcher.send_pointer(10, 20, 1));
  REQUIRE(watcher.send_pointer(10, 20, 0));
  REQUIRE(watcher.round_trip());  // it is served, and the server has read its input by now

  // A participant after it: its key arrives, so the watcher's would have arrived before it.
  ProxiedClient participant(proxied.server->port(), "PROXY TCP4 203.0.113.5 127.0.0.1 51234 5901\r\n");
  REQUIRE(participant.send_key('p', true));
  REQUIRE(participant.send_key('p', false));
  REQUIRE(participant.round_trip());
  std::vector<rfbsim::InputEvent> input;
  for (int i = 0; i < 500; ++i) {
    for (const auto& event : proxied.server->poll_input()) input.push_back(event);
    if (input.size() >= 2) break;
    std::this_thread::sleep_for(10ms);
  }
  REQUIRE(input.size() == 2);
  for (const auto& event : input) {
    CHECK(event.kind == rfbsim::InputEvent::Kind::Key);
    CHECK(event.keysym == 'p');
  }

  const auto clients = proxied.clients();
  REQUIRE(clients.size() == 2);
  CHECK(clients[0].view_only);
  CHECK(clients[0].address == "127.0.0.1");  // UNKNOWN names no address: the socket's peer
  CHECK_FALSE(clients[1].view_only);
  CHECK(clients[1].address == "203.0.113.5");
  CHECK(input[0].client_id == clients[1].id);
}

TEST_CASE("other text after UNKNOWN does not make a watcher") {
  ProxiedServer proxied(false);
  ProxiedClient client(proxied.server->port(), "PROXY UNKNOWN view-only please\r\n");
  REQUIRE(client.send_key('k', true));
  REQUIRE(client.round_trip());
  std::vector<rfbsim::InputEvent> input;
  for (int i = 0; i < 500 && input.empty(); ++i) {
    input = proxied.server->poll_input();
    if (input.empty()) std::this_thread::sleep_for(10ms);
  }
  REQUIRE(input.size() == 1);
  CHECK(input[0].keysym == 'k');
  REQUIRE(proxied.clients().size() == 1);
  CHECK_FALSE(proxied.clients()[0].view_only);
}
