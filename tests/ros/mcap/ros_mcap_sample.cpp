// SPDX-License-Identifier: GPL-2.0-or-later
// ros_mcap_sample: writes a small ROS 2 bag for the Node readers (mcap_read_test.mjs) to read back.
//
//   ros_mcap_sample FILE [--messages N] [--kill-after-chunks K]
//
// Three topics, round robin: /chatter (std_msgs/msg/String), /cmd_vel (geometry_msgs/msg/Twist, with its
// Vector3 dependency) and /scan (sensor_msgs/msg/LaserScan, with std_msgs/Header and builtin_interfaces/Time),
// message i logged at 1 s + i * 10 ms with values that are a function of i (mcap_read_test.mjs recomputes
// them). Chunks are small (2 KiB) so that the bag has many. With --kill-after-chunks K, it writes K chunks
// of 60 messages, leaves 7 more in an open chunk, waits until the K chunks are in the file and kills itself
// with SIGKILL before finish(). Prints one JSON line: {"messages": written, "in_chunks": closed into chunks}.
#include <signal.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "ros/mcap/cdr_writer.hpp"
#include "ros/mcap/mcap_writer.hpp"

using rfbsim::ros::CdrWriter;
using rfbsim::ros::McapOptions;
using rfbsim::ros::McapWriter;

namespace {

// ros2msg definitions (ROS 2 interface docs): the type, then each dependency after a line of 80 '='.
const std::string kSeparator = std::string(80, '=') + "\n";
const std::string kStringDef = "string data\n";
const std::string kTwistDef = "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n" + kSeparator +
                              "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";
const std::string kLaserScanDef =
    "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n"
    "float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\nfloat32[] ranges\n"
    "float32[] intensities\n" +
    kSeparator + "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n" + kSeparator +
    "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";

constexpr std::uint64_t kStartNs = 1'000'000'000;
constexpr std::uint64_t kStepNs = 10'000'000;

struct Topics {
  std::uint16_t chatter = 0, cmd_vel = 0, scan = 0;
};

// Message i on its topic, encoded as CDR.
void write_message(McapWriter& bag, const Topics& topics, int i) {
  const std::uint64_t t = kStartNs + static_cast<std::uint64_t>(i) * kStepNs;
  CdrWriter cdr;
  std::uint16_t channel = 0;
  switch (i % 3) {
    case 0:
      cdr.string("message " + std::to_string(i));
      channel = topics.chatter;
      break;
    case 1:
      cdr.f64(i * 0.5);  // linear
      cdr.f64(-i);
      cdr.f64(0.25);
      cdr.f64(0);  // angular
      cdr.f64(0);
      cdr.f64(i / 8.0);
      channel = topics.cmd_vel;
      break;
    default: {
      cdr.i32(static_cast<std::int32_t>(t / 1'000'000'000));  // header.stamp
      cdr.u32(static_cast<std::uint32_t>(t % 1'000'000'000));
      cdr.string("laser");
      for (const float v : {-1.5F, 1.5F, 0.25F, 0.0F, 0.1F, 0.1F, 10.0F}) cdr.f32(v);
      std::vector<float> ranges(static_cast<std::size_t>(1 + i % 5));
      for (std::size_t k = 0; k < ranges.size(); ++k) ranges[k] = static_cast<float>(i + static_cast<int>(k)) * 0.5F;
      cdr.sequence_length(ranges.size());
      cdr.f32_array(ranges.data(), ranges.size());
      cdr.sequence_length(0);  // no intensities
      channel = topics.scan;
      break;
    }
  }
  bag.write(channel, t, t, cdr.data().data(), cdr.data().size());
}

int run(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: ros_mcap_sample FILE [--messages N] [--kill-after-chunks K]\n");
    return 2;
  }
  int messages = 900;
  int kill_after = -1;
  for (int a = 2; a + 1 < argc; a += 2) {
    if (std::strcmp(argv[a], "--messages") == 0) messages = std::atoi(argv[a + 1]);
    else if (std::strcmp(argv[a], "--kill-after-chunks") == 0) kill_after = std::atoi(argv[a + 1]);
    else {
      std::fprintf(stderr, "ros_mcap_sample: unknown option %s\n", argv[a]);
      return 2;
    }
  }

  McapOptions options;
  options.chunk_bytes = kill_after < 0 ? 2048 : 1u << 20;  // killed: chunks closed by flush_if_due alone
  options.chunk_interval = std::chrono::milliseconds(0);
  McapWriter bag(argv[1], options);
  Topics topics;
  topics.chatter = bag.add_channel(bag.add_schema("std_msgs/msg/String", "ros2msg", kStringDef), "/chatter", "cdr");
  topics.cmd_vel = bag.add_channel(bag.add_schema("geometry_msgs/msg/Twist", "ros2msg", kTwistDef), "/cmd_vel", "cdr");
  topics.scan = bag.add_channel(bag.add_schema("sensor_msgs/msg/LaserScan", "ros2msg", kLaserScanDef), "/scan",
                                "cdr", {{"offered_qos_profiles", ""}});

  if (kill_after >= 0) {
    int i = 0;
    for (int k = 0; k < kill_after; ++k) {
      for (int m = 0; m < 60; ++m) write_message(bag, topics, i++);
      bag.flush_if_due();  // an interval of 0: closes the chunk
    }
    for (int m = 0; m < 7; ++m) write_message(bag, topics, i++);  // left open: lost with the process
    bag.drain();
    std::printf("{\"messages\": %d, \"in_chunks\": %d}\n", i, kill_after * 60);
    std::fflush(stdout);
    ::raise(SIGKILL);
    return 1;
  }
  for (int i = 0; i < messages; ++i) write_message(bag, topics, i);
  bag.finish();
  if (const auto failure = bag.failure()) {
    std::fprintf(stderr, "ros_mcap_sample: %s\n", failure->c_str());
    return 1;
  }
  std::printf("{\"messages\": %d, \"in_chunks\": %d}\n", messages, messages);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ros_mcap_sample: %s\n", e.what());
    return 1;
  }
}
