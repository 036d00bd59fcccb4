// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "app/options.hpp"

using rfbsim::sim::parse_sim_options;

TEST_CASE("defaults and every option") {
  const auto d = parse_sim_options({});
  CHECK(d.error.empty());
  CHECK(d.options.bind == "127.0.0.1");
  CHECK(d.options.width == 1280);
  const auto o = parse_sim_options({"--port", "0", "--width", "640", "--height", "480", "--fps", "60", "--seed", "42",
                                    "--bind", "0.0.0.0", "--quality", "90", "--max-clients", "2", "--egl",
                                    "surfaceless", "--web-root", "/tmp/w"});
  REQUIRE(o.error.empty());
  CHECK(o.options.port == 0);
  CHECK(o.options.width == 640);
  CHECK(o.options.height == 480);
  CHECK(o.options.fps == 60);
  CHECK(o.options.seed == 42);
  CHECK(o.options.bind == "0.0.0.0");
  CHECK(o.options.jpeg_quality == 90);
  CHECK(o.options.max_clients == 2);
  CHECK(o.options.egl_platform == "surfaceless");
  CHECK(o.options.web_root == "/tmp/w");
}

TEST_CASE("bad arguments are named") {
  CHECK(parse_sim_options({"--port"}).error == "--port needs a value");
  CHECK(parse_sim_options({"--port", "70000"}).error == "bad value '70000' for --port");
  CHECK(parse_sim_options({"--port", "12x"}).error == "bad value '12x' for --port");
  CHECK(parse_sim_options({"--width", "-5"}).error == "bad value '-5' for --width");
  CHECK(parse_sim_options({"--fps", "0"}).error == "bad value '0' for --fps");
  CHECK(parse_sim_options({"--egl", "x11"}).error == "bad value 'x11' for --egl");
  CHECK(parse_sim_options({"--frobnicate"}).error == "unknown argument '--frobnicate'");
  CHECK(parse_sim_options({"--help"}).options.help);
}
