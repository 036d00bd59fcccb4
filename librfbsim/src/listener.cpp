// SPDX-License-Identifier: GPL-2.0-or-later
// open_listener: getaddrinfo with numeric hosts only; we never resolve names. open_unix_listener: a
// socket file only its owner may connect to.
#include "listener.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace rfbsim::detail {

namespace {

// Connections the kernel completes before we accept them. The server accepts in batches and classifies
// them itself (ServerOptions::max_pending_connections), so a longer queue only smooths bursts.
constexpr int kBacklog = 128;

// Whether some process accepts connections on the unix socket at `address` now.
bool unix_socket_is_live(const sockaddr_un& address) {
  const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (probe < 0) return false;
  const bool live = ::connect(probe, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
  ::close(probe);
  return live;
}

}  // namespace

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
  if (::listen(fd, kBacklog) != 0) {
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

Listener open_unix_listener(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof address.sun_path) {
    const std::string longest = std::to_string(sizeof address.sun_path - 1);
    throw std::runtime_error("unix socket path '" + path + "' must be 1.." + longest + " bytes long");
  }
  path.copy(address.sun_path, path.size());
  // A file already there: a socket left by a crashed server is ours to replace; a live one or any other
  // file is not (we would cut off another server or destroy someone's data).
  struct stat existing {};
  if (::lstat(path.c_str(), &existing) == 0) {
    if (!S_ISSOCK(existing.st_mode)) throw std::runtime_error("'" + path + "' exists and is not a socket");
    if (unix_socket_is_live(address)) throw std::runtime_error("unix socket '" + path + "' is already in use");
    if (::unlink(path.c_str()) != 0 && errno != ENOENT) {
      throw std::runtime_error("cannot remove the stale socket '" + path + "': " + std::strerror(errno));
    }
  }
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) throw std::runtime_error(std::string("cannot create a unix socket: ") + std::strerror(errno));
  const auto fail = [&](const std::string& what, bool created) {
    const int error = errno;
    ::close(fd);
    if (created) ::unlink(path.c_str());
    throw std::runtime_error(what + " '" + path + "': " + std::strerror(error));
  };
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) fail("cannot bind", false);
  // Nobody can connect before listen(), so the mode is right before the first connection could come,
  // whatever the umask was (no process-wide umask change, which other threads would race with).
  if (::chmod(path.c_str(), S_IRUSR | S_IWUSR) != 0) fail("cannot make private", true);
  struct stat created {};
  if (::stat(path.c_str(), &created) != 0) fail("cannot stat", true);
  if (::listen(fd, kBacklog) != 0) fail("cannot listen on", true);
  Listener listener;
  listener.fd = fd;
  listener.unix_path = path;
  listener.unix_device = created.st_dev;
  listener.unix_inode = created.st_ino;
  return listener;
}

void close_listener(Listener& listener) {
  if (listener.fd >= 0) ::close(listener.fd);
  listener.fd = -1;
  if (listener.unix_path.empty()) return;
  // Only our own file: another server may have replaced it since (after deciding ours was stale).
  struct stat now {};
  if (::lstat(listener.unix_path.c_str(), &now) == 0 && now.st_dev == listener.unix_device &&
      now.st_ino == listener.unix_inode) {
    ::unlink(listener.unix_path.c_str());
  }
  listener.unix_path.clear();
}

}  // namespace rfbsim::detail
