// SPDX-License-Identifier: GPL-2.0-or-later
// Test helper: a tiny tmpfs mounted for one test, so that a full disk is a real one. Mounting needs root
// (or CAP_SYS_ADMIN); where it is refused the test says so and passes over that case.
#pragma once

#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace rfbsim::test {

class SmallTmpfs {
 public:
  /// Mounts a tmpfs of `bytes` on the (existing, empty) folder `dir`; mounted() says whether it worked.
  SmallTmpfs(std::filesystem::path dir, std::size_t bytes) : dir_(std::move(dir)) {
    const std::string data = "size=" + std::to_string(bytes) + ",mode=0700";
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, data.c_str()) == 0) {
      mounted_ = true;
    } else {
      why_not_ = std::string("cannot mount a tmpfs on ") + dir_.string() + " (" + std::strerror(errno) + ")";
    }
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
  std::filesystem::path dir_;
  bool mounted_ = false;
  std::string why_not_;
};

}  // namespace rfbsim::test
