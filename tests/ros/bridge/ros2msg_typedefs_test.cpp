// SPDX-License-Identifier: GPL-2.0-or-later
// ros2msg_typedefs on small hand-written definitions: every field form (primitive, nested with and without a package,
// unbounded, bounded and fixed arrays, bounded strings, defaults), constants, and the block order.
#include <catch2/catch.hpp>

#include "ros/bridge/ros2msg_typedefs.hpp"

using namespace rfbsim::ros;
using nlohmann::json;

TEST_CASE(
    "ros2msg_typedefs lists the type first, then each nested block, with "
    "rosapi's TypeDef fields") {
  const std::string rule(80, '=');
  const std::string text =
      "uint8 IDLE=0\nuint8 BUSY = 1\nstd_msgs/Header header\nPoint[] points\n"
      "float64[36] covariance\nint32[<=4] few\nstring<=8 label \"none\"\nbool "
      "on true\n\n" +
      rule +
      "\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring "
      "frame_id\n" +
      rule + "\nMSG: demo_msgs/Point\nfloat64 x\nfloat64 y\n";
  const json defs = ros2msg_typedefs("demo_msgs/Shape", text);
  REQUIRE(defs.size() == 3);
  const json& shape = defs[0];
  CHECK(shape["type"] == "demo_msgs/msg/Shape");
  CHECK(shape["fieldnames"] == json({"header", "points", "covariance", "few", "label", "on"}));
  CHECK(shape["fieldtypes"] ==
        json({"std_msgs/msg/Header", "demo_msgs/msg/Point", "float64", "int32", "string", "bool"}));
  CHECK(shape["fieldarraylen"] == json({-1, 0, 36, 0, -1, -1}));
  CHECK(shape["examples"] == json({"{}", "[]", "[]", "[]", "", "False"}));
  CHECK(shape["constnames"] == json({"IDLE", "BUSY"}));
  CHECK(shape["constvalues"] == json({"0", "1"}));
  CHECK(defs[1]["type"] == "std_msgs/msg/Header");
  CHECK(defs[1]["fieldtypes"] == json({"builtin_interfaces/msg/Time", "string"}));
  CHECK(defs[2]["type"] == "demo_msgs/msg/Point");
  CHECK(defs[2]["fieldnames"] == json({"x", "y"}));
  CHECK(defs[2]["examples"] == json({"0", "0"}));
}

TEST_CASE(
    "ros2msg_typedefs answers nothing for an empty definition or a "
    "malformed type") {
  CHECK(ros2msg_typedefs("demo_msgs/msg/Point", "").empty());
  CHECK(ros2msg_typedefs("demo_msgs/msg/Point", " \n").empty());
  CHECK(ros2msg_typedefs("not a type", "float64 x\n").empty());
  // One block, no trailing newline.
  CHECK(ros2msg_typedefs("demo_msgs/msg/Point", "float64 x")[0]["fieldnames"] == json({"x"}));
}
