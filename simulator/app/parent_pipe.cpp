// SPDX-License-Identifier: GPL-2.0-or-later
#include "app/parent_pipe.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace rfbsim::sim {

void check_ready_fd(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0) {
    throw std::runtime_error("--ready-fd " + std::to_string(fd) + ": not an open file descriptor (" +
                             std::strerror(errno) + ")");
  }
  if ((flags & O_ACCMODE) == O_RDONLY) {
    throw std::runtime_error("--ready-fd " + std::to_string(fd) + ": open for reading only");
  }
}

std::string write_line(int fd, const std::string& line) {
  std::size_t written = 0;
  while (written < line.size()) {
    const auto n = ::write(fd, line.data() + written, line.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? std::strerror(errno) : "nothing written";
    written += static_cast<std::size_t>(n);
  }
  return "";
}

}  // namespace rfbsim::sim
