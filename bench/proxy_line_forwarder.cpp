// SPDX-License-Identifier: GPL-2.0-or-later
// The PROXY-line forwarder; see proxy_line_forwarder.hpp.
#include "proxy_line_forwarder.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <stdexcept>
#include <string>

namespace rfbsim::bench {

namespace {

constexpr int kPollMs = 100;  // how often a loop looks at stopping_

sockaddr_in loopback(int port) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return address;
}

// Writes all of `data`; false when the peer is gone.
bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t wrote = ::send(fd, data, size, MSG_NOSIGNAL);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) return false;
    data += wrote;
    size -= static_cast<std::size_t>(wrote);
  }
  return true;
}

}  // namespace

ProxyLineForwarder::ProxyLineForwarder(int target_port) : target_port_(target_port) {
  listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address = loopback(0);
  socklen_t length = sizeof address;
  if (listener_ < 0 || ::bind(listener_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(listener_, 16) != 0 || ::getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    if (listener_ >= 0) ::close(listener_);
    throw std::runtime_error("ProxyLineForwarder: cannot listen on loopback");
  }
  port_ = ntohs(address.sin_port);
  acceptor_ = std::thread([this] { accept_loop(); });
}

ProxyLineForwarder::~ProxyLineForwarder() {
  stopping_ = true;
  acceptor_.join();
  ::close(listener_);
  const std::lock_guard lock(mutex_);
  for (std::thread& t : connections_) t.join();
}

void ProxyLineForwarder::accept_loop() {
  while (!stopping_) {
    pollfd ready{listener_, POLLIN, 0};
    if (::poll(&ready, 1, kPollMs) <= 0) continue;
    const int client = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    const std::lock_guard lock(mutex_);
    connections_.emplace_back([this, client] { relay(client); });
  }
}

void ProxyLineForwarder::relay(int client) {
  const int server = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const sockaddr_in target = loopback(target_port_);
  sockaddr_in peer{};
  socklen_t length = sizeof peer;
  ::getpeername(client, reinterpret_cast<sockaddr*>(&peer), &length);
  const int on = 1;
  // As the manager's relay: no Nagle, so an update's tail is not held for a delayed ACK.
  ::setsockopt(client, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
  const std::string line = "PROXY TCP4 127.0.0.1 127.0.0.1 " + std::to_string(ntohs(peer.sin_port)) + " " +
                           std::to_string(target_port_) + "\r\n";
  if (server >= 0 && ::setsockopt(server, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on) == 0 &&
      ::connect(server, reinterpret_cast<const sockaddr*>(&target), sizeof target) == 0 &&
      write_all(server, line.data(), line.size())) {
    // Both ways until either side closes or the forwarder stops.
    std::array<char, 65536> buffer{};
    std::array<pollfd, 2> fds{pollfd{client, POLLIN, 0}, pollfd{server, POLLIN, 0}};
    bool open = true;
    while (open && !stopping_) {
      if (::poll(fds.data(), fds.size(), kPollMs) <= 0) continue;
      for (std::size_t i = 0; i < fds.size() && open; ++i) {
        if (fds[i].revents == 0) continue;
        const ssize_t got = ::recv(fds[i].fd, buffer.data(), buffer.size(), 0);
        open = got > 0 && write_all(fds[1 - i].fd, buffer.data(), static_cast<std::size_t>(got));
      }
    }
  }
  if (server >= 0) ::close(server);
  ::close(client);
}

}  // namespace rfbsim::bench
