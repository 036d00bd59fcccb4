// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim_x11_session's flags: a good command line, each kind of bad one, and Xvnc's exact argv.
#include "session_options.hpp"

#include <algorithm>
#include <catch2/catch.hpp>

#include "xvnc_command.hpp"

using rfbsim::x11::parse_session_options;
using Args = std::vector<std::string>;

namespace {

Args good() {
  return {"--rfb-socket", "/d/rfb.sock", "--xauthority", "/d/xauth", "--geometry", "640x480",
          "--",           "glxgears",    "-info"};
}

// The error for `args`, "" when they parse.
std::string error_of(const Args& args) { return parse_session_options(args).error; }

}  // namespace

TEST_CASE("x11 session flags: a full command line", "[x11]") {
  Args args = good();
  args.insert(args.begin(), {"--depth", "16", "--ready-fd=5", "--xvnc", "/opt/Xvnc"});
  const auto parsed = parse_session_options(args);
  REQUIRE(parsed.error.empty());
  CHECK(parsed.options.rfb_socket == "/d/rfb.sock");
  CHECK(parsed.options.xauthority == "/d/xauth");
  CHECK(parsed.options.width == 640);
  CHECK(parsed.options.height == 480);
  CHECK(parsed.options.depth == 16);
  CHECK(parsed.options.ready_fd == 5);
  CHECK(parsed.options.xvnc == "/opt/Xvnc");
  CHECK(parsed.options.program == Args{"glxgears", "-info"});
}

TEST_CASE("x11 session flags: defaults, and the program's own flags after --", "[x11]") {
  const auto parsed = parse_session_options({"--rfb-socket=/s", "--xauthority=/x", "--geometry=16x8192", "--", "prog",
                                             "--geometry", "--"});
  REQUIRE(parsed.error.empty());
  CHECK(parsed.options.depth == 24);
  CHECK(parsed.options.ready_fd == -1);
  CHECK(parsed.options.xvnc == "/usr/bin/Xvnc");
  CHECK(parsed.options.program == Args{"prog", "--geometry", "--"});
  CHECK(parse_session_options({"--help"}).help);
}

TEST_CASE("x11 session flags: each bad command line names its problem", "[x11]") {
  const auto without = [](const std::string& flag) {
    Args args = good();
    const auto at = std::find(args.begin(), args.end(), flag);
    args.erase(at, at + 2);
    return args;
  };
  CHECK(error_of(without("--rfb-socket")) == "--rfb-socket is required");
  CHECK(error_of(without("--xauthority")) == "--xauthority is required");
  CHECK(error_of(without("--geometry")) == "--geometry is required");
  CHECK(error_of({"--rfb-socket", "/s", "--xauthority", "/x", "--geometry", "64x64"}) ==
        "no program: name it after '--'");
  CHECK(error_of({"--rfb-socket", "/s", "--xauthority", "/x", "--geometry", "64x64", "--"}) ==
        "no program: name it after '--'");

  for (const std::string geometry : {"640", "640x", "x480", "axb", "0x0", "15x100", "100x8193", "-64x64", "64x64x",
                                     "99999999999x1", " 64x64"}) {
    Args args = good();
    args[5] = geometry;
    CHECK(error_of(args) == "bad value '" + geometry + "' for --geometry (expected WxH with each side in 16..8192)");
  }
  Args args = good();
  args.insert(args.begin(), {"--depth", "8"});
  CHECK(error_of(args) == "bad value '8' for --depth (expected 16 or 24)");
  for (const std::string fd : {"2", "0", "x", "", "-1", "3.5"}) {
    args = good();
    args.insert(args.begin(), {"--ready-fd", fd});
    CHECK(error_of(args) == "bad value '" + fd + "' for --ready-fd");
  }
  CHECK(error_of({"--rfb-socket"}) == "--rfb-socket needs a value");
  CHECK(error_of({"--color", "red"}) == "unknown argument '--color'");
  CHECK(error_of({"glxgears"}) == "'glxgears' is not a flag (the program goes after '--')");
  args = good();
  args.insert(args.begin(), {"--geometry", "64x64"});
  CHECK(error_of(args) == "--geometry is given more than once");
  args = good();
  args[7] = "";
  CHECK(error_of(args) == "no program: name it after '--'");
}

TEST_CASE("x11 session flags: --log-level takes the log's level names", "[x11]") {
  CHECK(parse_session_options(good()).options.log_level == "info");
  Args args = good();
  args.insert(args.begin(), {"--log-level", "debug"});
  const auto parsed = parse_session_options(args);
  REQUIRE(parsed.error.empty());
  CHECK(parsed.options.log_level == "debug");
  args[1] = "loud";
  CHECK(error_of(args) == "bad value 'loud' for --log-level (expected error, warn, info or debug)");
}

TEST_CASE("x11 session flags: the RFB socket path fits a unix address", "[x11]") {
  Args args = good();
  args[1] = "/" + std::string(106, 'a');  // 107 bytes and the NUL: the most sun_path holds
  CHECK(error_of(args).empty());
  args[1] += "a";
  CHECK(error_of(args) == "bad value '" + args[1] + "' for --rfb-socket (expected a path of 1 to 107 bytes)");
  args[1] = "";
  CHECK(error_of(args) == "bad value '' for --rfb-socket (expected a path of 1 to 107 bytes)");
}

TEST_CASE("Xvnc's argv: private display, cookie, 0600 unix socket only, fixed size", "[x11]") {
  const auto parsed = parse_session_options(good());
  REQUIRE(parsed.error.empty());
  CHECK(rfbsim::x11::xvnc_arguments(parsed.options, 7) ==
        Args{"/usr/bin/Xvnc", "-displayfd", "7", "-auth", "/d/xauth", "-nolisten", "tcp", "-rfbunixpath", "/d/rfb.sock",
             "-rfbunixmode", "0600", "-rfbport", "-1", "-SecurityTypes", "None", "-AlwaysShared",
             "-AcceptSetDesktopSize=0", "-geometry", "640x480", "-depth", "24", "-desktop", "glxgears"});
  rfbsim::x11::SessionOptions options = parsed.options;
  options.program = {"/opt/unity/Build.x86_64"};
  CHECK(rfbsim::x11::xvnc_arguments(options, 7).back() == "Build.x86_64");
}

TEST_CASE("the program's environment: DISPLAY and XAUTHORITY replaced, the rest kept in order", "[x11]") {
  CHECK(rfbsim::x11::program_environment({"PATH=/bin", "DISPLAY=:0", "LANG=C", "XAUTHORITY=/root/.Xauthority"}, 12,
                                         "/d/xauth") ==
        Args{"PATH=/bin", "LANG=C", "DISPLAY=:12", "XAUTHORITY=/d/xauth"});
}
