// SPDX-License-Identifier: GPL-2.0-or-later
// The Xauthority file format (Xau's XauWriteAuth): per entry, family as 2 bytes, then address, display number,
// name and data, each as a 2-byte big-endian length and the bytes. All big-endian.
#include "xauthority.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string_view>

namespace rfbsim::x11 {

namespace {

constexpr std::uint16_t kFamilyWild = 0xFFFF;
constexpr std::string_view kCookieName = "MIT-MAGIC-COOKIE-1";

void put_u16(std::string& out, std::size_t value) {
  out.push_back(static_cast<char>((value >> 8) & 0xFF));
  out.push_back(static_cast<char>(value & 0xFF));
}

void put_field(std::string& out, std::string_view bytes) {
  put_u16(out, bytes.size());
  out.append(bytes);
}

}  // namespace

std::string xauthority_entry(const Cookie& cookie) {
  std::string out;
  put_u16(out, kFamilyWild);
  put_field(out, "");  // address: any host
  put_field(out, "");  // display number: any display
  put_field(out, kCookieName);
  put_field(out, std::string_view(reinterpret_cast<const char*>(cookie.data()), cookie.size()));
  return out;
}

Cookie random_cookie() {
  Cookie cookie{};
  std::size_t got = 0;
  while (got < cookie.size()) {
    const ssize_t n = ::getrandom(cookie.data() + got, cookie.size() - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("no random bytes for the X cookie: ") + std::strerror(errno));
    got += static_cast<std::size_t>(n);
  }
  return cookie;
}

void write_xauthority(const std::string& path, const Cookie& cookie) {
  const auto fail = [&path](const std::string& what, int error) {
    throw std::runtime_error("cannot write the Xauthority file " + path + ": " + what + ": " + std::strerror(error));
  };
  const std::string bytes = xauthority_entry(cookie);

  // A new file of our own beside the target (mkostemp: O_EXCL, mode 0600), then an atomic rename over it.
  std::string temp = path + ".XXXXXX";
  const int fd = ::mkostemp(temp.data(), O_CLOEXEC);
  if (fd < 0) fail("create", errno);
  const auto discard = [&](const std::string& what) {
    const int error = errno;
    ::close(fd);
    ::unlink(temp.c_str());
    fail(what, error);
  };
  if (::fchmod(fd, 0600) != 0) discard("chmod");
  for (std::size_t written = 0; written < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n == 0) errno = EIO;  // a write that makes no progress: call it an I/O error
    if (n <= 0) discard("write");
    written += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) {
    const int error = errno;
    ::unlink(temp.c_str());
    fail("close", error);
  }
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temp.c_str());
    fail("rename", error);
  }
}

}  // namespace rfbsim::x11
