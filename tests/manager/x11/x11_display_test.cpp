// SPDX-License-Identifier: GPL-2.0-or-later
// remove_stale_display in a scratch folder standing for /tmp: a dead server's files go, a live one's stay.
#include "x11_display.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "launcher_run.hpp"
#include "scratch_dir.hpp"

using rfbsim::test::path_exists;
using rfbsim::test::ScratchDir;
using rfbsim::x11::display_lock_path;
using rfbsim::x11::display_socket_path;
using rfbsim::x11::remove_stale_display;

namespace {

constexpr int kDisplay = 57;

// A lock file as Xorg writes it.
void write_lock(const ScratchDir& dir, long pid) {
  char text[16];
  std::snprintf(text, sizeof text, "%10ld\n", pid);
  dir.write(".X57-lock", text);
}

// A unix socket bound at `path`; listening when `listen`. Returns its descriptor (closed by the caller).
int bound_socket(const std::string& path, bool listen) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, path.c_str(), sizeof address.sun_path - 1);
  REQUIRE(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0);
  if (listen) REQUIRE(::listen(fd, 1) == 0);
  return fd;
}

// The pid of a process that has exited and been reaped.
pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return pid;
}

}  // namespace

TEST_CASE("display paths are Xorg's", "[x11]") {
  CHECK(display_lock_path(3) == "/tmp/.X3-lock");
  CHECK(display_socket_path(3) == "/tmp/.X11-unix/X3");
  CHECK(display_socket_path(12, "/t") == "/t/.X11-unix/X12");
}

TEST_CASE("a dead server's lock and socket are removed", "[x11]") {
  ScratchDir dir("rfbsim_xdisp");
  std::filesystem::create_directory(dir.path() / ".X11-unix");
  const std::string tmp = dir.path().string();
  write_lock(dir, dead_pid());
  ::close(bound_socket(display_socket_path(kDisplay, tmp), true));  // closed: the file stays, nobody accepts
  REQUIRE(path_exists(display_socket_path(kDisplay, tmp)));
  CHECK(remove_stale_display(kDisplay, tmp));
  CHECK_FALSE(path_exists(display_lock_path(kDisplay, tmp)));
  CHECK_FALSE(path_exists(display_socket_path(kDisplay, tmp)));
  CHECK(remove_stale_display(kDisplay, tmp));  // nothing there: nothing to do
}

TEST_CASE("a lock of junk counts as stale", "[x11]") {
  ScratchDir dir("rfbsim_xdisp");
  const std::string tmp = dir.path().string();
  dir.write(".X57-lock", "not a pid\n");
  CHECK(remove_stale_display(kDisplay, tmp));
  CHECK_FALSE(path_exists(display_lock_path(kDisplay, tmp)));
}

TEST_CASE("a live server's display is left alone", "[x11]") {
  ScratchDir dir("rfbsim_xdisp");
  std::filesystem::create_directory(dir.path() / ".X11-unix");
  const std::string tmp = dir.path().string();

  SECTION("its lock names a live pid") {
    write_lock(dir, ::getpid());
    CHECK_FALSE(remove_stale_display(kDisplay, tmp));
    CHECK(path_exists(display_lock_path(kDisplay, tmp)));
  }
  SECTION("no lock (Xvnc -displayfd writes none), but it accepts on its socket") {
    const int fd = bound_socket(display_socket_path(kDisplay, tmp), true);
    CHECK_FALSE(remove_stale_display(kDisplay, tmp));
    CHECK(path_exists(display_socket_path(kDisplay, tmp)));
    ::close(fd);
  }
  SECTION("a bad display number touches nothing") {
    write_lock(dir, dead_pid());
    CHECK_FALSE(remove_stale_display(-1, tmp));
    CHECK(path_exists(display_lock_path(kDisplay, tmp)));
  }
}
