// SPDX-License-Identifier: GPL-2.0-or-later
// open_listener: getaddrinfo with numeric hosts only; we never resolve names.
#include "listener.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace rfbsim::detail {

Listener open_listener(const std::string& address, int port) {
  if (port < 0 || port > 65535) throw std::runtime_error("port " + std::to_string(port) + " is out of range");
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICHOST | AI_NUMERICSERV | AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (::getaddrinfo(address.c_str(), service.c_str(), &hints, &found) != 0 || found == nullptr) {
    throw std::runtime_error("bind address '" + address + "' is not a numeric IPv4 or IPv6 address");
  }
  const int fd = ::socket(found->ai_family, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) {
    ::freeaddrinfo(found);
    throw std::runtime_error(std::string("cannot create a socket: ") + std::strerror(errno));
  }
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  const int bound = ::bind(fd, found->ai_addr, found->ai_addrlen);
  const int bind_errno = errno;
  ::freeaddrinfo(found);
  if (bound != 0) {
    ::close(fd);
    const std::string where = address + ":" + std::to_string(port);
    if (bind_errno == EADDRINUSE) throw std::runtime_error("port " + std::to_string(port) + " is already in use on " + address);
    throw std::runtime_error("cannot bind " + where + ": " + std::strerror(bind_errno));
  }
  if (::listen(fd, 64) != 0) {
    const int listen_errno = errno;
    ::close(fd);
    throw std::runtime_error(std::string("cannot listen: ") + std::strerror(listen_errno));
  }
  sockaddr_storage local{};
  socklen_t length = sizeof local;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &length);
  Listener listener;
  listener.fd = fd;
  listener.port = local.ss_family == AF_INET6 ? ntohs(reinterpret_cast<sockaddr_in6*>(&local)->sin6_port)
                                              : ntohs(reinterpret_cast<sockaddr_in*>(&local)->sin_port);
  return listener;
}

}  // namespace rfbsim::detail
