// SPDX-License-Identifier: GPL-2.0-or-later
// The intake of new connections under abuse: the list of connections not yet classified stays bounded
// (the oldest make room) while real clients are served, a half-sent PROXY line or request head keeps no
// thread busy, and running out of file descriptors pauses accepting instead of spinning on it.
#include <catch2/catch.hpp>

#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>
#include <netinet/in.h>
#include <arpa/inet.h>

#include <algorithm>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "misbehaving_clients.hpp"
#include "raw_socket.hpp"
#include "rfb_wire.hpp"
#include "rfbsim/server.hpp"
#include "served_scene.hpp"

using rfbsim::test::eventually;
using rfbsim::test::kPatience;
using rfbsim::test::RawSocket;
using namespace std::chrono_literals;

namespace {

constexpr int kIntakeWidth = 64;
constexpr int kIntakeHeight = 48;
constexpr int kIdleConnections = 500;

rfbsim::ServerOptions intake_server() {
  rfbsim::ServerOptions options;
  options.width = kIntakeWidth;
  options.height = kIntakeHeight;
  return options;
}

void submit_grey(rfbsim::Server& server) {
  const std::vector<std::uint8_t> grey(static_cast<std::size_t>(kIntakeWidth) * kIntakeHeight * 4U, 128);
  server.submit(rfbsim::FrameView{grey.data(), kIntakeWidth, kIntakeHeight, 0});
}

// Which of `sockets` the server has closed (they sent nothing and were sent nothing: readable = EOF).
std::vector<bool> closed_by_server(const std::vector<std::unique_ptr<RawSocket>>& sockets) {
  std::vector<pollfd> fds;
  for (const auto& socket : sockets) fds.push_back({socket->fd(), POLLIN, 0});
  ::poll(fds.data(), fds.size(), 0);
  std::vector<bool> closed;
  for (const auto& p : fds) closed.push_back((p.revents & (POLLIN | POLLHUP | POLLERR)) != 0);
  return closed;
}

int count(const std::vector<bool>& flags) {
  return static_cast<int>(std::count(flags.begin(), flags.end(), true));
}

// CPU seconds this process used (all threads, user and system).
double process_cpu_seconds() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) / 1e6;
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// The share of one core this process used over `wall` while the test thread only called `every_100ms`
// ten times a second: the server's threads, nearly. A thread spinning on a socket would make it near 1.
template <typename Action>
double cpu_share_while(std::chrono::milliseconds wall, Action every_100ms) {
  const double before = process_cpu_seconds();
  const auto started = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - started < wall) {
    every_100ms();
    std::this_thread::sleep_for(100ms);
  }
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return (process_cpu_seconds() - before) / elapsed;
}

// A proxied client (PROXY line, then a hand-made RFB handshake) gets a whole first frame.
bool proxied_client_gets_frame(int port) {
  RawSocket socket(port);
  if (!socket.send_all("PROXY TCP4 198.51.100.7 127.0.0.1 40000 5901\r\n")) return false;
  const auto init = rfbsim::test::raw_rfb_handshake(socket);
  const rfbsim::test::ReadExact read = [&](std::size_t n, std::vector<std::uint8_t>& out) {
    return socket.read_exact(n, out, 5s);
  };
  if (!socket.send_all(rfbsim::test::rfb_update_request(false, 0, 0, init.width, init.height))) return false;
  const auto rects = rfbsim::test::rfb_read_raw_update(read, init.bits_per_pixel / 8);
  return !rects.empty() && rects[0].w == kIntakeWidth && rects[0].h == kIntakeHeight;
}

}  // namespace

TEST_CASE("500 idle connections: exactly the newest max_pending_connections wait, a real client is served",
          "[robustness][intake]") {
  // Behind a relay an idle connection waits up to read_timeout for its PROXY line: long enough here for all
  // of them to pile up in the intake list, which must keep only the newest 64 (the default cap).
  rfbsim::ServerOptions options = intake_server();
  options.proxy_protocol = true;
  options.read_timeout = std::chrono::milliseconds(30000);
  rfbsim::Server server(options);
  submit_grey(server);
  REQUIRE(server.options().max_pending_connections == 64);

  std::vector<std::unique_ptr<RawSocket>> idle;
  for (int i = 0; i < kIdleConnections; ++i) idle.push_back(std::make_unique<RawSocket>(server.port()));
  const int cap = server.options().max_pending_connections;
  CHECK(eventually([&] { return count(closed_by_server(idle)) == kIdleConnections - cap; }, kPatience));
  std::this_thread::sleep_for(300ms);  // and it stays so: nothing else is closed meanwhile
  const auto closed = closed_by_server(idle);
  CHECK(count(closed) == kIdleConnections - cap);
  // The oldest made room: the survivors are the last ones that came.
  for (int i = kIdleConnections - cap; i < kIdleConnections; ++i) CHECK_FALSE(closed[static_cast<std::size_t>(i)]);

  // None of the idle connections became an RFB client; the real one is served. (Counting clients after
  // proxied_client_gets_frame raced with the server noticing that its socket had closed.)
  CHECK(server.client_count() == 0);
  CHECK(proxied_client_gets_frame(server.port()));
}

TEST_CASE("500 idle connections on a plain port: the connected client keeps getting fresh frames",
          "[robustness][intake]") {
  // Idle connections end up as raw RFB clients after the sniff wait, take the free client slots, and the
  // rest are refused at once; the good client's frames go on meanwhile.
  rfbsim::test::ServedScene scene(intake_server());
  std::vector<std::unique_ptr<RawSocket>> idle;
  for (int i = 0; i < kIdleConnections; ++i) idle.push_back(std::make_unique<RawSocket>(scene.port()));
  CHECK(scene.good_client_gets_fresh_frame());
  CHECK(eventually([&] { return count(closed_by_server(idle)) >= kIdleConnections - 3; }, kPatience));
  CHECK(scene.good_client_gets_fresh_frame());
  CHECK(scene.server().client_count() <= scene.server().options().max_clients);
  idle.clear();
  scene.check_still_serving();
  UNSCOPED_INFO("longest wait for a fresh frame: " << scene.longest_wait().count() << " ms");
}

TEST_CASE("a half-sent PROXY line or request head keeps no thread busy", "[robustness][intake][waits]") {
  struct Case {
    const char* name;
    bool http;
    bool proxy;
    std::string bytes;
  };
  const std::vector<Case> cases = {
      {"request head, page served", true, false, "GET / HTTP/1.1\r\nHost: x"},
      {"request head, RFB only", false, false, "GET / HTTP/1.1\r\nHost: x"},
      {"PROXY line", true, true, "PROXY TCP4 203.0.113.5"},
      {"PROXY line, then a request head", true, true, "PROXY TCP4 203.0.113.5 127.0.0.1 1 2\r\nGET / HTTP/1.1\r\n"},
  };
  for (const auto& c : cases) {
    INFO(c.name);
    rfbsim::ServerOptions options = intake_server();
    if (c.http) options.json_routes["/status.json"] = [] { return std::string("{}"); };
    options.proxy_protocol = c.proxy;
    options.read_timeout = std::chrono::milliseconds(5000);  // the PROXY line's wait outlasts the measurement
    rfbsim::Server server(options);
    // A fresh half-sent connection every 100 ms, so that one is always inside the intake's wait (0.1 or
    // 0.5 s before a head goes to an HTTP worker): a spin there would show for the whole measurement.
    std::vector<std::unique_ptr<RawSocket>> sockets;
    const double share = cpu_share_while(2000ms, [&] {
      sockets.push_back(std::make_unique<RawSocket>(server.port()));
      REQUIRE(sockets.back()->send_all(c.bytes));
    });
    // A spin would use most of a core; waiting threads use next to nothing. Generous for a shared machine.
    UNSCOPED_INFO(c.name << ": " << share * 100 << " % of a core");
    CHECK(share < 0.2);
  }
}

TEST_CASE("out of file descriptors the server pauses accepting instead of spinning, then catches up",
          "[robustness][intake]") {
  rfbsim::Server server(intake_server());
  submit_grey(server);
  // A socket made now, connected once the process has no descriptor left: the kernel completes the
  // connection, and every accept4 the server tries fails with EMFILE until descriptors come back.
  const int client = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  REQUIRE(client >= 0);
  rlimit saved{};
  REQUIRE(::getrlimit(RLIMIT_NOFILE, &saved) == 0);
  rlimit lowered = saved;
  lowered.rlim_cur = 256;
  REQUIRE(::setrlimit(RLIMIT_NOFILE, &lowered) == 0);
  std::vector<int> filler;
  for (int fd = ::dup(0); fd >= 0; fd = ::dup(0)) filler.push_back(fd);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(server.port()));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool connected = ::connect(client, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;

  const double share = connected ? cpu_share_while(2000ms, [] {}) : 1.0;
  // The limit first, then the fillers: closed one by one under the low limit, the first freed descriptor would
  // go to the accept and none be left for the server's guard duplicate, which then refuses the client (by
  // design, with a log line: a clean-clone CI run met that order once).
  ::setrlimit(RLIMIT_NOFILE, &saved);
  for (const int fd : filler) ::close(fd);
  REQUIRE(connected);
  UNSCOPED_INFO("at EMFILE: " << share * 100 << " % of a core");
  CHECK(share < 0.2);

  // Descriptors back: the waiting connection is accepted and greeted as a raw RFB client.
  pollfd p{client, POLLIN, 0};
  char greeting[12] = {};
  const bool greeted = ::poll(&p, 1, static_cast<int>(kPatience.count())) == 1 &&
                       ::recv(client, greeting, sizeof greeting, MSG_WAITALL) == static_cast<ssize_t>(sizeof greeting);
  ::close(client);
  CHECK(greeted);
  CHECK(std::string(greeting, sizeof greeting) == "RFB 003.008\n");
}

TEST_CASE("a client that never finishes the RFB handshake gives its slot back after 10 s",
          "[robustness][intake][waits]") {
  rfbsim::ServerOptions options = intake_server();
  options.max_clients = 1;
  rfbsim::Server server(options);
  submit_grey(server);
  RawSocket idle(server.port());
  REQUIRE(idle.read_until("\n", 5s) == "RFB 003.008\n");  // greeted, then silent: it holds the one slot
  // The greeting goes out as the client is made; it is counted a moment later.
  CHECK(eventually([&] { return server.client_count() == 1; }, kPatience));
  CHECK_THROWS(rfbsim::test::RfbTestClient("127.0.0.1", server.port()));
  bool closed = false;
  idle.read_until_closed(20s, &closed);
  CHECK(closed);
  CHECK(eventually([&] { return server.client_count() == 0; }, kPatience));
  rfbsim::test::RfbTestClient client("127.0.0.1", server.port());
  CHECK(client.wait_for_updates(1, kPatience));
}
