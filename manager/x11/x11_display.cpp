// SPDX-License-Identifier: GPL-2.0-or-later
// Stale X display files: a lock is stale when its pid is gone; a socket is stale when connecting to it is refused.
#include "x11_display.hpp"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <csignal>
#include <cstring>
#include <fstream>

namespace rfbsim::x11 {

std::string display_lock_path(int display, const std::string& tmp_dir) {
  return tmp_dir + "/.X" + std::to_string(display) + "-lock";
}

std::string display_socket_path(int display, const std::string& tmp_dir) {
  return tmp_dir + "/.X11-unix/X" + std::to_string(display);
}

namespace {

// The pid in a lock file ("%10d\n": spaces, digits, newline); 0 when the file is not that.
long lock_pid(const std::string& path) {
  std::ifstream in(path);
  long pid = 0;
  if (!(in >> pid) || pid <= 0) return 0;
  return pid;
}

bool pid_alive(long pid) {
  // EPERM: it exists but is another user's; still alive.
  return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

// Whether a server accepts connections on the unix socket `name` (abstract when `abstract`). Only "refused" and
// "no such socket" count as nobody: any other failure (a full backlog, no permission) is taken as in use.
bool someone_listens(const std::string& name, bool abstract) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::size_t offset = abstract ? 1 : 0;  // abstract names start with a NUL byte
  if (name.size() + offset >= sizeof address.sun_path) return false;
  std::memcpy(address.sun_path + offset, name.data(), name.size());
  const auto length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + offset + name.size());
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return true;
  const int result = ::connect(fd, reinterpret_cast<const sockaddr*>(&address), length);
  const int error = errno;
  ::close(fd);
  return result == 0 || (error != ECONNREFUSED && error != ENOENT);
}

bool exists(const std::string& path) {
  struct stat info {};
  return ::lstat(path.c_str(), &info) == 0;
}

}  // namespace

bool remove_stale_display(int display, const std::string& tmp_dir) {
  if (display < 0) return false;
  const std::string lock = display_lock_path(display, tmp_dir);
  const std::string socket = display_socket_path(display, tmp_dir);

  // The lock first: a live pid there means the display is someone's, whatever its socket says.
  if (exists(lock)) {
    if (pid_alive(lock_pid(lock))) return false;
    if (::unlink(lock.c_str()) != 0 && errno != ENOENT) return false;
  }
  // A server started with -displayfd writes no lock: its listening sockets are the only sign of it. The abstract
  // socket goes with the process even after a SIGKILL, so it is checked too (a new server on this number
  // binds that one first).
  if (someone_listens(socket, true)) return false;
  if (exists(socket)) {
    if (someone_listens(socket, false)) return false;
    if (::unlink(socket.c_str()) != 0 && errno != ENOENT) return false;
  }
  return true;
}

}  // namespace rfbsim::x11
