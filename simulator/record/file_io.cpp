// SPDX-License-Identifier: GPL-2.0-or-later
// File steps for session data: write, sync, replace, reserve.
#include "record/file_io.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace rfbsim::sim {

namespace {

FileResult failed(const std::string& name, const char* what, int error, std::size_t written = 0) {
  return {one_line(name + ": " + what + " (" + std::strerror(error) + ")"), written};
}

}  // namespace

UniqueFd& UniqueFd::operator=(UniqueFd&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.release();
  }
  return *this;
}

UniqueFd::~UniqueFd() {
  if (fd_ >= 0) ::close(fd_);
}

int UniqueFd::release() { return std::exchange(fd_, -1); }

UniqueFd open_append(const std::filesystem::path& path, std::string& error) {
  // 0600: session data names no one, but it is the participant's, not every local user's.
  UniqueFd fd(::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600));
  if (!fd.valid()) error = failed(path.string(), "cannot open for writing", errno).error;
  return fd;
}

UniqueFd open_dir(const std::filesystem::path& dir, std::string& error) {
  UniqueFd fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (!fd.valid()) error = failed(dir.string(), "cannot open the folder", errno).error;
  return fd;
}

FileResult write_all(int fd, std::string_view bytes, const std::string& name) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    // A write of 0 bytes to a regular file means no room: say so as the kernel would have.
    if (n <= 0) return failed(name, "cannot write", n < 0 ? errno : ENOSPC, done);
    done += static_cast<std::size_t>(n);
  }
  return {"", done};
}

FileResult sync_data(int fd, const std::string& name) {
  if (::fdatasync(fd) != 0) return failed(name, "cannot sync", errno);
  return {};
}

FileResult sync_dir(int dir_fd, const std::string& name) {
  if (::fsync(dir_fd) != 0) return failed(name, "cannot sync the folder", errno);
  return {};
}

FileResult replace_file(const std::filesystem::path& dir, int dir_fd, const std::string& name, std::string_view text) {
  const std::string temporary_name = name + ".tmp";
  const std::filesystem::path temporary = dir / temporary_name;
  UniqueFd fd(::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600));
  if (!fd.valid()) return failed(temporary_name, "cannot open for writing", errno);
  FileResult result = write_all(fd.get(), text, temporary_name);
  if (result.ok()) result = sync_data(fd.get(), temporary_name);
  if (!result.ok()) {
    // Leave no half document behind: the old one stays in place.
    ::unlink(temporary.c_str());
    return result;
  }
  fd = UniqueFd();
  if (::rename(temporary.c_str(), (dir / name).c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    return failed(name, "cannot replace", error);
  }
  return sync_dir(dir_fd, name);
}

FileResult reserve_space(const std::filesystem::path& path, std::size_t bytes) {
  const std::string name = path.filename().string();
  UniqueFd fd(::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600));
  if (!fd.valid()) return failed(name, "cannot open for writing", errno);
  // posix_fallocate returns the error rather than setting errno.
  if (const int error = ::posix_fallocate(fd.get(), 0, static_cast<off_t>(bytes)); error != 0) {
    ::unlink(path.c_str());
    return failed(name, "cannot set space aside", error);
  }
  FileResult result = sync_data(fd.get(), name);
  if (!result.ok()) ::unlink(path.c_str());
  return result;
}

std::string one_line(std::string_view text, std::size_t limit) {
  std::string line(text.substr(0, limit));
  for (char& c : line) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  }
  return line;
}

}  // namespace rfbsim::sim
