// SPDX-License-Identifier: GPL-2.0-or-later
// A server behind a trusted relay (ServerOptions::proxy_protocol): the PROXY line's source address becomes
// the client's, and a connection that does not begin with a valid line is closed without harm to the rest.
#include <catch2/catch.hpp>

#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "raw_socket.hpp"
#include "rfbsim/server.hpp"

using rfbsim::test::RawSocket;

namespace {

struct ProxiedServer {
  std::mutex mutex;
  std::vector<std::string> addresses;
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
    };
    server = std::make_unique<rfbsim::Server>(std::move(options));
  }
  std::vector<std::string> seen() {
    std::lock_guard lock(mutex);
    return addresses;
  }
  // libvncserver sends its greeting before it calls the new-client hook: wait for the hook a little.
  std::vector<std::string> seen_once_connected() {
    for (int i = 0; i < 500 && seen().empty(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return seen();
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
