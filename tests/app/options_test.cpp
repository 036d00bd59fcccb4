// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "app/options.hpp"

using rfbsim::sim::parse_sim_options;

TEST_CASE("defaults and every option") {
  const auto d = parse_sim_options({});
  CHECK(d.error.empty());
  CHECK(d.options.bind == "127.0.0.1");
  CHECK(d.options.width == 1280);
  CHECK_FALSE(d.options.seed);  // the scenario's seed unless one is given
  CHECK(d.options.scenario.empty());
  const auto o = parse_sim_options({"--port", "0", "--width", "640", "--height", "480", "--fps", "60", "--seed", "42",
                                    "--bind", "0.0.0.0", "--quality", "90", "--max-clients", "2", "--egl",
                                    "surfaceless", "--web-root", "/tmp/w"});
  REQUIRE(o.error.empty());
  CHECK(o.options.port == 0);
  CHECK(o.options.width == 640);
  CHECK(o.options.height == 480);
  CHECK(o.options.fps == 60);
  CHECK(o.options.seed == std::uint64_t{42});
  CHECK(o.options.bind == "0.0.0.0");
  CHECK(o.options.jpeg_quality == 90);
  CHECK(o.options.max_clients == 2);
  CHECK(o.options.egl_platform == "surfaceless");
  CHECK(o.options.web_root == "/tmp/w");
}

TEST_CASE("scenario options are kept for the scenario loader to check") {
  const auto o = parse_sim_options({"--scenario", "warehouse", "--avatar-start", "dock", "--avatar-goal", "1.5,2",
                                    "--robot-start", "3,4,1.57", "--robot-goal", "aisle_1", "--crowd", "0"});
  REQUIRE(o.error.empty());
  CHECK(o.options.scenario == "warehouse");
  CHECK(o.options.avatar_start == std::string("dock"));
  CHECK(o.options.avatar_goal == std::string("1.5,2"));
  CHECK(o.options.robot_start == std::string("3,4,1.57"));
  CHECK(o.options.robot_goal == std::string("aisle_1"));
  CHECK(o.options.crowd == 0);
  CHECK(parse_sim_options({"--crowd", "501"}).error == "bad value '501' for --crowd");
  CHECK(parse_sim_options({"--crowd", "-1"}).error == "bad value '-1' for --crowd");
  CHECK(parse_sim_options({"--scenario", ""}).error == "bad value '' for --scenario");
}

TEST_CASE("bad arguments are named") {
  CHECK(parse_sim_options({"--port"}).error == "--port needs a value");
  CHECK(parse_sim_options({"--port", "70000"}).error == "bad value '70000' for --port");
  CHECK(parse_sim_options({"--port", "12x"}).error == "bad value '12x' for --port");
  CHECK(parse_sim_options({"--width", "-5"}).error == "bad value '-5' for --width");
  CHECK(parse_sim_options({"--fps", "0"}).error == "bad value '0' for --fps");
  CHECK(parse_sim_options({"--egl", "x11"}).error == "bad value 'x11' for --egl (expected auto, device or surfaceless)");
  CHECK(parse_sim_options({"--frobnicate"}).error == "unknown argument '--frobnicate'");
  CHECK(parse_sim_options({"--help"}).options.help);
}

TEST_CASE("the debug overlay flag is off by default, takes no value, and is in the usage text") {
  CHECK_FALSE(parse_sim_options({}).options.debug_overlay);
  const auto o = parse_sim_options({"--debug-overlay", "--port", "0"});
  REQUIRE(o.error.empty());
  CHECK(o.options.debug_overlay);
  CHECK(o.options.port == 0);  // the flag takes no value: the next option is still read
  CHECK(parse_sim_options({"--port", "0", "--debug-overlay"}).options.debug_overlay);
  CHECK(parse_sim_options({"--debug-overlay=1"}).error == "unknown argument '--debug-overlay=1'");
  CHECK(rfbsim::sim::sim_usage().find("--debug-overlay") != std::string::npos);
}

TEST_CASE("the ready fd option takes a descriptor of 3 or above") {
  CHECK_FALSE(parse_sim_options({}).options.ready_fd);
  const auto o = parse_sim_options({"--ready-fd", "3", "--port", "0"});
  REQUIRE(o.error.empty());
  CHECK(o.options.ready_fd == 3);
  CHECK(o.options.port == 0);
  CHECK(parse_sim_options({"--ready-fd", "1023"}).options.ready_fd == 1023);
  // stdin, stdout and stderr are refused: the ready line belongs on a pipe of its own.
  for (const char* fd : {"0", "1", "2"}) {
    CHECK(parse_sim_options({"--ready-fd", fd}).error == std::string("bad value '") + fd + "' for --ready-fd");
  }
  CHECK(parse_sim_options({"--ready-fd", "-3"}).error == "bad value '-3' for --ready-fd");
  CHECK(parse_sim_options({"--ready-fd", "three"}).error == "bad value 'three' for --ready-fd");
  CHECK(parse_sim_options({"--ready-fd", "3x"}).error == "bad value '3x' for --ready-fd");
  CHECK(parse_sim_options({"--ready-fd", ""}).error == "bad value '' for --ready-fd");
  CHECK(parse_sim_options({"--ready-fd", "99999999999"}).error == "bad value '99999999999' for --ready-fd");
  CHECK(parse_sim_options({"--ready-fd"}).error == "--ready-fd needs a value");
  CHECK(rfbsim::sim::sim_usage().find("--ready-fd N") != std::string::npos);
}

TEST_CASE("the rfb-only flag takes no value and excludes --web-root") {
  CHECK_FALSE(parse_sim_options({}).options.rfb_only);
  const auto o = parse_sim_options({"--rfb-only", "--port", "0"});
  REQUIRE(o.error.empty());
  CHECK(o.options.rfb_only);
  CHECK(o.options.port == 0);  // the flag takes no value: the next option is still read
  CHECK(parse_sim_options({"--port", "0", "--rfb-only"}).options.rfb_only);
  CHECK(parse_sim_options({"--rfb-only=1"}).error == "unknown argument '--rfb-only=1'");
  CHECK(parse_sim_options({"--rfb-only", "--web-root", "/tmp/w"}).error == "--rfb-only serves no page; drop --web-root");
  CHECK(parse_sim_options({"--web-root", "/tmp/w", "--rfb-only"}).error == "--rfb-only serves no page; drop --web-root");
  CHECK(rfbsim::sim::sim_usage().find("--rfb-only") != std::string::npos);
}

TEST_CASE("the codec option takes auto, jpeg or h264 and names the choices when it is wrong") {
  CHECK(parse_sim_options({}).options.codec == "auto");
  for (const char* codec : {"auto", "jpeg", "h264"}) {
    const auto o = parse_sim_options({"--codec", codec, "--port", "0"});
    REQUIRE(o.error.empty());
    CHECK(o.options.codec == codec);
    CHECK(o.options.port == 0);
  }
  CHECK(parse_sim_options({"--codec", "H264"}).error == "bad value 'H264' for --codec (expected auto, jpeg or h264)");
  CHECK(parse_sim_options({"--codec", "tight"}).error == "bad value 'tight' for --codec (expected auto, jpeg or h264)");
  CHECK(parse_sim_options({"--codec", ""}).error == "bad value '' for --codec (expected auto, jpeg or h264)");
  CHECK(parse_sim_options({"--codec"}).error == "--codec needs a value");
  CHECK(rfbsim::sim::sim_usage().find("--codec auto|jpeg|h264") != std::string::npos);
}

TEST_CASE("the end grace option takes whole seconds from 0 to 3600 and is unset by default") {
  CHECK_FALSE(parse_sim_options({}).options.end_grace);
  CHECK(parse_sim_options({"--end-grace", "0"}).options.end_grace == 0);
  CHECK(parse_sim_options({"--end-grace", "3600"}).options.end_grace == 3600);
  CHECK(parse_sim_options({"--end-grace", "3601"}).error == "bad value '3601' for --end-grace");
  CHECK(parse_sim_options({"--end-grace", "-1"}).error == "bad value '-1' for --end-grace");
  CHECK(parse_sim_options({"--end-grace", "2.5"}).error == "bad value '2.5' for --end-grace");
}

TEST_CASE("the replay option takes a session folder and refuses options that would make another world") {
  CHECK(parse_sim_options({}).options.replay.empty());
  const auto o = parse_sim_options({"--replay", "/data/7-p-01", "--port", "0", "--data-dir", "/data/8-w", "--uid", "w"});
  REQUIRE(o.error.empty());
  CHECK(o.options.replay == "/data/7-p-01");
  CHECK(parse_sim_options({"--replay", ""}).error == "bad value '' for --replay");
  for (const char* other : {"--scenario", "--seed", "--crowd", "--time-limit", "--avatar-start", "--robot-goal"}) {
    const std::string value = std::string(other) == "--scenario" ? "lab" : "3";
    const auto both = parse_sim_options({"--replay", "/data/7-p-01", other, value});
    INFO(other << ": " << both.error);
    CHECK(both.error.find("--replay") != std::string::npos);
    CHECK(both.error.find(other) != std::string::npos);
  }
}

TEST_CASE("the camera option takes third_person or first_person and is unset by default (the scenario's)") {
  CHECK_FALSE(parse_sim_options({}).options.camera.has_value());
  for (const char* camera : {"third_person", "first_person"}) {
    const auto o = parse_sim_options({"--camera", camera});
    REQUIRE(o.error.empty());
    CHECK(o.options.camera == camera);
  }
  CHECK(parse_sim_options({"--camera", "overhead"}).error ==
        "bad value 'overhead' for --camera (expected third_person or first_person)");
  CHECK(rfbsim::sim::sim_usage().find("--camera third_person|first_person") != std::string::npos);
}
