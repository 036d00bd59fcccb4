// SPDX-License-Identifier: GPL-2.0-or-later
// Test helper: a tiny tmpfs mounted for one test, so that a full disk is a real one. Mounting needs root or
// CAP_SYS_ADMIN. Without them the test process moves into a user and mount namespace of its own, where it may
// mount (Debian allows unprivileged user namespaces); the programs it then starts share that view. Where both
// are refused, why_not() says why and the test skips (tests/support/skip.hpp).
#pragma once

#include <fcntl.h>
#include <sched.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace rfbsim::test {

class SmallTmpfs {
 public:
  /// Mounts a tmpfs of `bytes` on the (existing, empty) folder `dir`; mounted() says whether it worked.
  /// Call it before the test starts threads: a multithreaded process cannot enter a new user namespace.
  SmallTmpfs(std::filesystem::path dir, std::size_t bytes) : dir_(std::move(dir)) {
    if (try_mount(bytes)) return;
    const std::string refused = std::strerror(errno);
    if (::geteuid() != 0) {
      const std::string entered = enter_private_namespaces();
      if (entered.empty() && try_mount(bytes)) return;
      why_not_ = "cannot mount a tmpfs on " + dir_.string() + " (" + refused + "), nor in a user namespace (" +
                 (entered.empty() ? std::string(std::strerror(errno)) : entered) + "): run as root, or allow " +
                 "unprivileged user namespaces";
      return;
    }
    why_not_ = "cannot mount a tmpfs on " + dir_.string() + " (" + refused + ")";
  }
  /// Unmounts (lazily, should a file still be open).
  ~SmallTmpfs() {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
  }
  SmallTmpfs(const SmallTmpfs&) = delete;
  SmallTmpfs& operator=(const SmallTmpfs&) = delete;

  [[nodiscard]] bool mounted() const { return mounted_; }
  /// Why the mount was refused ("" when mounted).
  [[nodiscard]] const std::string& why_not() const { return why_not_; }

 private:
  bool try_mount(std::size_t bytes) {
    const std::string data = "size=" + std::to_string(bytes) + ",mode=0700";
    mounted_ = ::mount("tmpfs", dir_.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, data.c_str()) == 0;
    return mounted_;
  }

  // Unshares a user namespace in which this process is root (its own uid and gid mapped to 0) and a mount
  // namespace owned by it; "" on success, else what failed.
  static std::string enter_private_namespaces() {
    const uid_t uid = ::geteuid();
    const gid_t gid = ::getegid();
    if (::unshare(CLONE_NEWUSER | CLONE_NEWNS) != 0) return std::string("unshare: ") + std::strerror(errno);
    const auto write_file = [](const char* path, const std::string& text) {
      const int fd = ::open(path, O_WRONLY | O_CLOEXEC);
      if (fd < 0) return false;
      const bool whole = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
      ::close(fd);
      return whole;
    };
    if (!write_file("/proc/self/setgroups", "deny") ||
        !write_file("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1\n") ||
        !write_file("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1\n")) {
      return std::string("mapping the user: ") + std::strerror(errno);
    }
    return "";
  }

  std::filesystem::path dir_;
  bool mounted_ = false;
  std::string why_not_;
};

}  // namespace rfbsim::test
