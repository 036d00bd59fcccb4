// SPDX-License-Identifier: GPL-2.0-or-later
// SourceForwarder: accept, connect from the chosen source, then poll() and copy both ways.
#include "source_forwarder.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>

namespace rfbsim::test {

namespace {

sockaddr_in loopback(const std::string& address, int port) {
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(static_cast<std::uint16_t>(port));
  if (::inet_pton(AF_INET, address.c_str(), &sa.sin_addr) != 1) {
    throw std::runtime_error("source forwarder: '" + address + "' is not an IPv4 address");
  }
  return sa;
}

// Writes all of `data`; false when the peer is gone.
bool write_all(int fd, const char* data, ssize_t size) {
  while (size > 0) {
    const ssize_t n = ::send(fd, data, static_cast<std::size_t>(size), MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= n;
  }
  return true;
}

}  // namespace

SourceForwarder::SourceForwarder(const std::string& source_address, int target_port)
    : source_(source_address), target_port_(target_port) {
  loopback(source_, 0);  // checks the address before anything is opened
  listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listener_ < 0) throw std::runtime_error("source forwarder: socket failed");
  sockaddr_in sa = loopback("127.0.0.1", 0);
  socklen_t length = sizeof sa;
  if (::bind(listener_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0 || ::listen(listener_, 64) != 0 ||
      ::getsockname(listener_, reinterpret_cast<sockaddr*>(&sa), &length) != 0) {
    ::close(listener_);
    throw std::runtime_error("source forwarder: cannot listen on 127.0.0.1");
  }
  port_ = ntohs(sa.sin_port);
  acceptor_ = std::thread([this] { accept_loop(); });
}

SourceForwarder::~SourceForwarder() {
  stop_ = true;
  ::shutdown(listener_, SHUT_RDWR);  // wakes the acceptor's poll
  acceptor_.join();
  for (std::thread& pump : pumps_) pump.join();
  ::close(listener_);
}

void SourceForwarder::accept_loop() {
  while (!stop_) {
    pollfd p{listener_, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const int client = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    const int upstream = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const sockaddr_in from = loopback(source_, 0);
    const sockaddr_in to = loopback("127.0.0.1", target_port_);
    if (upstream < 0 || ::bind(upstream, reinterpret_cast<const sockaddr*>(&from), sizeof from) != 0 ||
        ::connect(upstream, reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0) {
      if (upstream >= 0) ::close(upstream);
      ::close(client);  // the client sees the refusal as a closed connection
      continue;
    }
    pumps_.emplace_back([this, client, upstream] { pump(client, upstream); });
  }
}

void SourceForwarder::pump(int client, int upstream) {
  pollfd fds[2] = {{client, POLLIN, 0}, {upstream, POLLIN, 0}};
  char buffer[16384];
  while (!stop_) {
    if (::poll(fds, 2, 100) <= 0) continue;
    bool done = false;
    for (int i = 0; i < 2 && !done; ++i) {
      if ((fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
      const ssize_t n = ::recv(fds[i].fd, buffer, sizeof buffer, 0);
      if (n < 0 && errno == EINTR) continue;
      done = n <= 0 || !write_all(fds[1 - i].fd, buffer, n);
    }
    if (done) break;
  }
  ::close(client);
  ::close(upstream);
}

}  // namespace rfbsim::test
