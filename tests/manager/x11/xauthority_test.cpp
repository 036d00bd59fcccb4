// SPDX-License-Identifier: GPL-2.0-or-later
// The Xauthority writer: the exact bytes of the one entry, mode 0600, and a safe replace.
#include "xauthority.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>

#include "scratch_dir.hpp"

using rfbsim::test::ScratchDir;
using rfbsim::x11::Cookie;

namespace {

Cookie counting_cookie() {
  Cookie cookie{};
  for (std::size_t i = 0; i < cookie.size(); ++i) cookie[i] = static_cast<std::uint8_t>(i * 17);
  return cookie;
}

}  // namespace

TEST_CASE("an Xauthority entry: FamilyWild, no address, no display number, MIT-MAGIC-COOKIE-1, 16 bytes", "[x11]") {
  const std::string entry = rfbsim::x11::xauthority_entry(counting_cookie());
  std::string expected("\xFF\xFF\x00\x00\x00\x00\x00\x12", 8);
  expected += "MIT-MAGIC-COOKIE-1";
  expected += std::string("\x00\x10", 2);
  for (std::size_t i = 0; i < 16; ++i) expected.push_back(static_cast<char>(i * 17));
  CHECK(entry.size() == 44);
  CHECK(entry == expected);
}

TEST_CASE("random cookies differ", "[x11]") {
  CHECK(rfbsim::x11::random_cookie() != rfbsim::x11::random_cookie());
}

TEST_CASE("the Xauthority file: mode 0600 whatever the umask, the entry's bytes, no temp file left", "[x11]") {
  ScratchDir dir("rfbsim_xauth");
  const mode_t old_mask = ::umask(0);
  rfbsim::x11::write_xauthority(dir.path("xauth"), counting_cookie());
  ::umask(old_mask);
  struct stat info {};
  REQUIRE(::stat(dir.path("xauth").c_str(), &info) == 0);
  CHECK((info.st_mode & 07777) == 0600);
  CHECK(dir.read("xauth") == rfbsim::x11::xauthority_entry(counting_cookie()));
  CHECK(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()) == 1);
}

TEST_CASE("the Xauthority file replaces a file or a link at its path and never writes through the link", "[x11]") {
  ScratchDir dir("rfbsim_xauth");
  const std::string target = dir.write("elsewhere", "keep me");
  REQUIRE(::symlink(target.c_str(), dir.path("xauth").c_str()) == 0);
  rfbsim::x11::write_xauthority(dir.path("xauth"), counting_cookie());
  CHECK(dir.read("elsewhere") == "keep me");
  CHECK(std::filesystem::is_regular_file(std::filesystem::symlink_status(dir.path("xauth"))));

  dir.write("plain", "old");
  rfbsim::x11::write_xauthority(dir.path("plain"), counting_cookie());
  CHECK(dir.read("plain").size() == 44);
}

TEST_CASE("an Xauthority file in a missing folder is an error naming the path", "[x11]") {
  ScratchDir dir("rfbsim_xauth");
  const std::string path = dir.path("no/such/xauth");
  CHECK_THROWS_WITH(rfbsim::x11::write_xauthority(path, counting_cookie()),
                    Catch::Contains(path) && Catch::Contains("No such file"));
}
