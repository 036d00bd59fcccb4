// SPDX-License-Identifier: GPL-2.0-or-later
// RawSocket: poll-with-deadline send and receive on a plain loopback TCP socket.
#include "raw_socket.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>

namespace rfbsim::test {

namespace {

using Clock = std::chrono::steady_clock;

// Milliseconds left until `deadline`, never negative.
int ms_left(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left > 0 ? static_cast<int>(left) : 0;
}

// Waits for `events` on `fd` until the deadline; true when ready (or in error, which the caller sees next).
bool wait_for(int fd, short events, Clock::time_point deadline) {
  for (;;) {
    pollfd pfd{fd, events, 0};
    const int n = ::poll(&pfd, 1, ms_left(deadline));
    if (n > 0) return true;
    if (n == 0) return false;
    if (errno != EINTR) return false;
  }
}

}  // namespace

RawSocket::RawSocket(int port, int receive_buffer) {
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error("socket() failed");
  if (receive_buffer > 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd_);
    fd_ = -1;
    throw std::runtime_error("cannot connect to 127.0.0.1:" + std::to_string(port));
  }
  const int one = 1;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

RawSocket::~RawSocket() { close(); }

bool RawSocket::send_all(std::string_view bytes, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!bytes.empty()) {
    const auto n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      bytes.remove_prefix(static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return false;
    if (!wait_for(fd_, POLLOUT, deadline)) return false;
  }
  return true;
}

bool RawSocket::send_all(const std::vector<std::uint8_t>& bytes, std::chrono::milliseconds timeout) {
  return send_all(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), timeout);
}

bool RawSocket::read_exact(std::size_t count, std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  out.assign(count, 0);
  std::size_t got = 0;
  while (got < count) {
    const auto n = ::recv(fd_, out.data() + got, count - got, MSG_DONTWAIT);
    if (n > 0) {
      got += static_cast<std::size_t>(n);
      continue;
    }
    if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) || !wait_for(fd_, POLLIN, deadline)) {
      out.resize(got);
      return false;
    }
  }
  return true;
}

std::string RawSocket::read_until_closed(std::chrono::milliseconds timeout, bool* closed) {
  const auto deadline = Clock::now() + timeout;
  std::string received;
  if (closed != nullptr) *closed = false;
  for (;;) {
    char buffer[65536];
    const auto n = ::recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n > 0) {
      received.append(buffer, static_cast<std::size_t>(n));
      continue;
    }
    if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
      if (closed != nullptr) *closed = true;  // EOF, or ECONNRESET from a peer that closed with data unread
      return received;
    }
    if (!wait_for(fd_, POLLIN, deadline)) return received;
  }
}

std::string RawSocket::read_until(std::string_view terminator, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  std::string received;
  while (received.size() < terminator.size() ||
         received.compare(received.size() - terminator.size(), terminator.size(), terminator) != 0) {
    char c = 0;
    const auto n = ::recv(fd_, &c, 1, MSG_DONTWAIT);
    if (n == 1) {
      received.push_back(c);
      continue;
    }
    if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) return {};
    if (!wait_for(fd_, POLLIN, deadline)) return {};
  }
  return received;
}

void RawSocket::reset() {
  if (fd_ < 0) return;
  const linger abort_on_close{1, 0};
  ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &abort_on_close, sizeof abort_on_close);
  ::close(fd_);
  fd_ = -1;
}

void RawSocket::close() {
  if (fd_ < 0) return;
  ::close(fd_);
  fd_ = -1;
}

}  // namespace rfbsim::test
