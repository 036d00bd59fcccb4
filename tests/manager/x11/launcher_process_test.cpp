// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim_x11_session as a real process: real Xvnc, our key-echo X11 program, a libvncclient client on the 0600
// unix socket. Each session's life ends one way (SIGTERM, the program exiting, Xvnc dying, SIGKILL of the whole
// group) and nothing may be left: no process of the group, no X lock or socket, no RFB socket, no Xauthority.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "launcher_run.hpp"
#include "rfb_test_client.hpp"
#include "scratch_dir.hpp"
#include "skip.hpp"
#include "x11_display_check.hpp"
#include "x11_display.hpp"

using namespace std::chrono_literals;
using rfbsim::test::LauncherRun;
using rfbsim::test::path_exists;
using rfbsim::test::ScratchDir;
using rfbsim::test::display_left_behind;

namespace {

// Generous: these bound a hang on a loaded machine, they measure nothing.
constexpr auto kLong = 20s;

// Skips the test (or fails it, under RFBSIM_NO_SKIP=1) where Xvnc or the key-echo program is missing.
#define SKIP_WITHOUT_X11()                                                                              \
  if (const std::string missing = rfbsim::test::x11_missing(); !missing.empty()) RFBSIM_SKIP(missing)

// The flags for a 320x240 session in `dir`.
std::vector<std::string> session_flags(const ScratchDir& dir) {
  return {"--rfb-socket", dir.path("rfb.sock"), "--xauthority", dir.path("xauth"), "--geometry", "320x240"};
}

// The display number from the ready lines, after checking them whole; -1 if they are not as agreed or the pipe
// did not close (someone kept a copy: the launcher must hand it to neither child).
int display_from_ready(const std::optional<std::string>& text, const ScratchDir& dir) {
  if (!text) return -1;
  const std::string& ready = *text;
  const std::string first = "ready unix " + dir.path("rfb.sock") + "\nx11 display ";
  if (ready.rfind(first, 0) != 0 || ready.empty() || ready.back() != '\n') return -1;
  return std::stoi(ready.substr(first.size()));
}

// What a session leaves when it ended well: nothing.
void check_nothing_left(const ScratchDir& dir, int display, pid_t group) {
  CHECK_FALSE(path_exists(dir.path("rfb.sock")));
  CHECK_FALSE(path_exists(dir.path("xauth")));
  CHECK_FALSE(display_left_behind(display));
  CHECK_FALSE(rfbsim::test::group_has_live_member(group));
}

// The mean of the picture's red, green and blue (0..255).
double mean_level(const rfbsim::FrameView& frame) {
  double sum = 0;
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      for (int c = 0; c < 3; ++c) sum += frame.row(y)[x * 4 + c];
    }
  }
  return sum / (3.0 * frame.width * frame.height);
}

}  // namespace

TEST_CASE("an X11 program served over the unix socket: frames, a key reaches it, SIGTERM leaves nothing",
          "[x11][process]") {
  SKIP_WITHOUT_X11();
  ScratchDir dir("rfbsim_x11");
  LauncherRun run(dir.path().string(), session_flags(dir), {rfbsim::test::kKeyEchoBinary});
  const int display = display_from_ready(run.ready_text(kLong), dir);
  REQUIRE(display >= 0);
  REQUIRE(run.wait_for_line("display :" + std::to_string(display), kLong));
  REQUIRE(run.wait_for_line("mapped 320x240", kLong));

  // Private: the RFB socket is the owner's alone, the cookie file too.
  struct stat info {};
  REQUIRE(::stat(dir.path("rfb.sock").c_str(), &info) == 0);
  CHECK(S_ISSOCK(info.st_mode));
  CHECK((info.st_mode & 0777) == 0600);
  REQUIRE(::stat(dir.path("xauth").c_str(), &info) == 0);
  CHECK((info.st_mode & 0777) == 0600);
  CHECK(path_exists(dir.path("xvnc.log")));

  {
    rfbsim::test::RfbTestClient client(dir.path("rfb.sock"), 0);
    CHECK(client.desktop_name() == "rfbsim_x11_key_echo");
    REQUIRE(client.width() == 320);
    REQUIRE(client.height() == 240);
    // The key-echo window's dark grey (48): a picture, not an empty black screen.
    REQUIRE(client.pump_until([&] { return client.updates() > 0 && mean_level(client.frame()) > 30; }, kLong));
    const double before = mean_level(client.frame());
    CHECK(before < 80);

    client.send_key(0x77, true);  // XK_w
    client.send_key(0x77, false);
    CHECK(run.wait_for_line("key w", kLong));
    // Every key colour has each channel at 128 or more.
    CHECK(client.pump_until([&] { return mean_level(client.frame()) > 120; }, kLong));
  }

  ::kill(run.pid(), SIGTERM);
  const auto status = run.wait_exit(kLong);
  REQUIRE(status.has_value());
  CHECK(WIFEXITED(*status));
  CHECK(WEXITSTATUS(*status) == 0);
  check_nothing_left(dir, display, run.pid());
}

TEST_CASE("a program without the session's cookie is refused, and with it, it connects", "[x11][process]") {
  SKIP_WITHOUT_X11();
  ScratchDir dir("rfbsim_x11");
  LauncherRun run(dir.path().string(), session_flags(dir), {"sleep", "60"});
  const int display = display_from_ready(run.ready_text(kLong), dir);
  REQUIRE(display >= 0);
  const auto probe = [&](const std::string& xauthority) {
    const std::string command = "DISPLAY=:" + std::to_string(display) + " XAUTHORITY=" + xauthority + " " +
                                rfbsim::test::kKeyEchoBinary + " --probe >/dev/null 2>&1";
    return std::system(command.c_str());
  };
  CHECK(probe("/dev/null") != 0);
  CHECK(probe(dir.path("xauth")) == 0);
  ::kill(run.pid(), SIGTERM);
  REQUIRE(run.wait_exit(kLong).has_value());
  check_nothing_left(dir, display, run.pid());
}

TEST_CASE("a program that exits at once ends the launcher with its status, and nothing is left", "[x11][process]") {
  SKIP_WITHOUT_X11();
  ScratchDir dir("rfbsim_x11");
  LauncherRun run(dir.path().string(), session_flags(dir), {"sh", "-c", "exit 7"});
  const int display = display_from_ready(run.ready_text(kLong), dir);
  REQUIRE(display >= 0);
  const auto status = run.wait_exit(kLong);
  REQUIRE(status.has_value());
  CHECK(WIFEXITED(*status));
  CHECK(WEXITSTATUS(*status) == 7);
  check_nothing_left(dir, display, run.pid());
}

TEST_CASE("the program gets only stdin, stdout and stderr", "[x11][process]") {
  SKIP_WITHOUT_X11();
  ScratchDir dir("rfbsim_x11");
  // sh waits for ls, which lists sh's descriptors.
  LauncherRun run(dir.path().string(), session_flags(dir), {"sh", "-c", "ls /proc/$$/fd"});
  const int display = display_from_ready(run.ready_text(kLong), dir);
  REQUIRE(display >= 0);
  REQUIRE(run.wait_exit(kLong).has_value());
  CHECK(run.wait_for_line("2", kLong));
  CHECK(run.output() == "display :" + std::to_string(display) + "\n0\n1\n2\n");
}

TEST_CASE("SIGTERM during start-up still cleans up", "[x11][process]") {
  SKIP_WITHOUT_X11();
  ScratchDir dir("rfbsim_x11");
  // A stop may come at any moment of the start; sent at once it may even find the launcher before it took
  // over SIGTERM (then it simply dies, having made nothing).
  for (const auto delay : {0ms, 50ms, 150ms}) {
    LauncherRun run(dir.path().string(), session_flags(dir), {"sleep", "60"});
    std::this_thread::sleep_for(delay);
    ::kill(run.pid(), SIGTERM);
    const auto status = run.wait_exit(kLong);
    REQUIRE(status.has_value());
    const bool clean_exit = WIFEXITED(*status) && WEXITSTATUS(*status) == 0;
    const bool killed_early = WIFSIGNALED(*status) && WTERMSIG(*status) == SIGTERM;
    CHECK((clean_exit || killed_early));
    CHECK_FALSE(path_exists(dir.path("xauth")));
    CHECK_FALSE(path_exists(dir.path("rfb.sock")));
    CHECK_FALSE(rfbsim::test::group_has_live_member(run.pid()));
  }
}

TEST_CASE("Xvnc dying stops the program, and the launcher exits 1 and cleans the display", "[x11][process]") {
  SKIP_WITHOUT_X11();
  ScratchDir dir("rfbsim_x11");
  LauncherRun run(dir.path().string(), session_flags(dir), {rfbsim::test::kKeyEchoBinary});
  const int display = display_from_ready(run.ready_text(kLong), dir);
  REQUIRE(display >= 0);
  REQUIRE(run.wait_for_line("mapped 320x240", kLong));
  // Xvnc is the launcher's first child; SIGKILL leaves its display socket for the launcher to clean.
  const std::vector<pid_t> children = rfbsim::test::children_of(run.pid());
  REQUIRE(children.size() == 2);
  ::kill(children.front(), SIGKILL);
  const auto status = run.wait_exit(kLong);
  REQUIRE(status.has_value());
  CHECK(WIFEXITED(*status));
  CHECK(WEXITSTATUS(*status) == 1);
  check_nothing_left(dir, display, run.pid());
}

TEST_CASE("after a SIGKILL of the whole group, remove_stale_display leaves nothing of the display",
          "[x11][process]") {
  SKIP_WITHOUT_X11();
  ScratchDir dir("rfbsim_x11");
  LauncherRun run(dir.path().string(), session_flags(dir), {rfbsim::test::kKeyEchoBinary});
  const int display = display_from_ready(run.ready_text(kLong), dir);
  REQUIRE(display >= 0);
  ::kill(-run.pid(), SIGKILL);
  REQUIRE(run.wait_exit(kLong).has_value());
  // What a killed Xvnc cannot remove stays until someone does.
  CHECK(path_exists(rfbsim::x11::display_socket_path(display)));
  // Xvnc, reparented, may still be on its way out: its abstract socket goes when it is gone. (A parallel test's
  // server may take the number meanwhile; then what is there is its, and not left behind.)
  bool cleaned = false;
  for (const auto deadline = std::chrono::steady_clock::now() + kLong;
       !cleaned && std::chrono::steady_clock::now() < deadline; std::this_thread::sleep_for(50ms)) {
    rfbsim::x11::remove_stale_display(display);
    cleaned = !display_left_behind(display);
  }
  CHECK(cleaned);
  CHECK_FALSE(rfbsim::test::group_has_live_member(run.pid()));
}

TEST_CASE("an Xvnc that cannot run or never names a display: exit 1, nothing left", "[x11][process]") {
  SKIP_WITHOUT_X11();
  ScratchDir dir("rfbsim_x11");
  for (const std::string xvnc : {"/nonexistent/Xvnc", "/bin/false"}) {
    std::vector<std::string> flags = session_flags(dir);
    flags.insert(flags.end(), {"--xvnc", xvnc});
    LauncherRun run(dir.path().string(), flags, {"sleep", "60"});
    CHECK(run.ready_text(kLong) == std::string());
    const auto status = run.wait_exit(kLong);
    REQUIRE(status.has_value());
    CHECK(WIFEXITED(*status));
    CHECK(WEXITSTATUS(*status) == 1);
    CHECK_FALSE(path_exists(dir.path("xauth")));
    CHECK_FALSE(rfbsim::test::group_has_live_member(run.pid()));
  }
}

TEST_CASE("bad flags and a closed ready descriptor: exit 2", "[x11][process]") {
  ScratchDir dir("rfbsim_x11");
  const std::string launcher = rfbsim::test::kX11SessionBinary;
  CHECK(WEXITSTATUS(std::system((launcher + " --geometry 1x1 -- true 2>/dev/null").c_str())) == 2);
  CHECK(WEXITSTATUS(std::system((launcher + " --rfb-socket " + dir.path("s") + " --xauthority " + dir.path("x") +
                                 " --geometry 64x64 --ready-fd 9 -- true 2>/dev/null 9>&-")
                                    .c_str())) == 2);
  // fd 3 closed: the launcher's own descriptors must not take its number and pass for the manager's pipe.
  CHECK(WEXITSTATUS(std::system((launcher + " --rfb-socket " + dir.path("s") + " --xauthority " + dir.path("x") +
                                 " --geometry 64x64 --ready-fd 3 -- true 2>/dev/null 3>&-")
                                    .c_str())) == 2);
  CHECK_FALSE(path_exists(dir.path("x")));
}
