// SPDX-License-Identifier: GPL-2.0-or-later
#include "sessions/socket_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace rfbsim::manager {

namespace {

// The lock a live manager holds inside its folder.
constexpr const char* kLockName = ".lock";

// FNV-1a, 64 bits: a name that stays the same from one build and run to the next for one data directory.
std::uint64_t fnv1a(const std::string& text) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char ch : text) {
    hash ^= static_cast<unsigned char>(ch);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

// Where the folders go: short, because a socket's path must fit in 108 bytes.
std::filesystem::path folder_base() {
  std::error_code ec;
  std::filesystem::path base = std::filesystem::temp_directory_path(ec);
  if (ec || base.string().size() > 40) base = "/tmp";
  return base;
}

}  // namespace

std::string socket_folder_name(const std::string& data_dir) {
  std::error_code ec;
  const std::string absolute = std::filesystem::absolute(data_dir, ec).lexically_normal().string();
  char name[40];
  std::snprintf(name, sizeof name, "rfbsim-manager-%016llx",
                static_cast<unsigned long long>(fnv1a(ec ? data_dir : absolute)));
  return name;
}

SocketFolder::SocketFolder(const std::string& data_dir) {
  const std::string path = (folder_base() / socket_folder_name(data_dir)).string();
  if (take(path)) return;
  // Not ours to use: a random folder, as before, which this run removes when it ends.
  std::string pattern = (folder_base() / "rfbsim-manager-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    note_ += std::string(note_.empty() ? "" : "; ") + "cannot make a folder for session sockets: " + std::strerror(errno);
    return;
  }
  path_ = pattern;
}

bool SocketFolder::take(const std::string& path) {
  if (::mkdir(path.c_str(), 0700) != 0 && errno != EEXIST) {
    note_ = "cannot make " + path + ": " + std::strerror(errno);
    return false;
  }
  // Only a real folder of this user's, private to it, is used: another user may have made the name first in
  // the shared /tmp, or put a link there.
  struct stat status {};
  if (::lstat(path.c_str(), &status) != 0 || !S_ISDIR(status.st_mode) || status.st_uid != ::geteuid() ||
      (status.st_mode & 077) != 0) {
    note_ = path + " is not a private folder of this user's; a fresh one is used";
    return false;
  }
  const std::string lock = path + "/" + kLockName;
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (lock_fd_ < 0 || ::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    note_ = path + " is held by another manager of the same data directory; a fresh folder is used";
    if (lock_fd_ >= 0) ::close(lock_fd_);
    lock_fd_ = -1;
    return false;
  }
  // Ours, and nobody else's now: whatever is left came from a manager that died without clearing it.
  int removed = 0;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().filename() == kLockName) continue;
    std::error_code ignored;
    removed += std::filesystem::remove_all(it->path(), ignored) > 0 ? 1 : 0;
  }
  if (removed > 0) note_ = "removed " + std::to_string(removed) + " leftover(s) of a previous run from " + path;
  path_ = path;
  return true;
}

SocketFolder::~SocketFolder() {
  if (!path_.empty()) {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

}  // namespace rfbsim::manager
