// SPDX-License-Identifier: GPL-2.0-or-later
// Whether an X display's files in /tmp outlived their server. Header-only, for the x11 tests. Tests run in
// parallel (ctest -j) and Xvnc -displayfd takes the lowest free number, so another test's live server may hold a
// display number by the time a test looks: its files are not left behind.
#pragma once

#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace rfbsim::test {

/// Whether something accepts connections on the unix stream socket at `path`.
inline bool unix_socket_accepts(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  path.copy(address.sun_path, sizeof(address.sun_path) - 1);
  const bool accepted = ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  ::close(fd);
  return accepted;
}

/// Whether display `display` left files behind: a lock file naming a pid that is gone, or an X socket nobody
/// accepts on.
inline bool display_left_behind(int display) {
  const std::string lock = "/tmp/.X" + std::to_string(display) + "-lock";
  const std::string socket = "/tmp/.X11-unix/X" + std::to_string(display);
  std::error_code ec;
  if (std::filesystem::exists(lock, ec)) {
    std::ifstream in(lock);
    int pid = 0;
    in >> pid;
    if (pid <= 0 || ::kill(pid, 0) != 0) return true;
  }
  return std::filesystem::exists(socket, ec) && !unix_socket_accepts(socket);
}

}  // namespace rfbsim::test
