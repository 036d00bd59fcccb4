// SPDX-License-Identifier: GPL-2.0-or-later
// POSIX file steps for session data, each returning its failure in words instead of throwing, so that the
// writer thread can decide what a failure means: whole writes, syncs, an atomic replace with its folder
// synced, and space set aside for later.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace rfbsim::sim {

/// A descriptor closed with its owner.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept;
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  ~UniqueFd();

  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] bool valid() const { return fd_ >= 0; }
  int release();

 private:
  int fd_ = -1;
};

/// What one step did: `error` is "" on success, else "<file name>: <what> (<strerror>)" on one line.
struct FileResult {
  std::string error;
  std::size_t written = 0;  ///< bytes that reached the file, also when it failed partway

  [[nodiscard]] bool ok() const { return error.empty(); }
};

/// Opens `path` for appending (created 0600 when missing). Invalid with `error` set when it cannot.
UniqueFd open_append(const std::filesystem::path& path, std::string& error);

/// Opens the folder `dir` for fsync. Invalid with `error` set when it cannot.
UniqueFd open_dir(const std::filesystem::path& dir, std::string& error);

/// Writes all of `bytes` to `fd` (retrying short writes and EINTR). On failure `written` says how much went.
FileResult write_all(int fd, std::string_view bytes, const std::string& name);

/// fdatasync, with the failure named after `name`.
FileResult sync_data(int fd, const std::string& name);

/// fsync of a folder, so that names created, renamed or removed in it survive a power cut.
FileResult sync_dir(int dir_fd, const std::string& name);

/// Replaces `dir/name` with `text` atomically: `name.tmp` written and synced, renamed over, the folder
/// synced. A reader or a crash sees the old or the new file, never half of one.
FileResult replace_file(const std::filesystem::path& dir, int dir_fd, const std::string& name, std::string_view text);

/// Creates `path` holding `bytes` allocated bytes (posix_fallocate), synced, for removal when space runs out.
FileResult reserve_space(const std::filesystem::path& path, std::size_t bytes);

/// `text` as one line of at most `limit` bytes: newlines and other control characters become spaces.
std::string one_line(std::string_view text, std::size_t limit = 200);

}  // namespace rfbsim::sim
