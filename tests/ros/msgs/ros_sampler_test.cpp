// SPDX-License-Identifier: GPL-2.0-or-later
// RosWorldSampler on a small real simulation (walled room, a crate, a landmark, two walkers, the avatar walking,
// the robot driving to a goal): how many messages each topic gets over two simulated seconds, latched ones once,
// /scan once per sweep, /cmd_vel once per command, exact times, and frames that compose to the robot's belief.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "app/simulation.hpp"
#include "ros/msgs/ros_topics.hpp"

namespace ros = rfbsim::ros;
namespace sim = rfbsim::sim;

namespace {

constexpr int kTicks = 120;  // 2 s at 60 Hz
const sim::Pose2 kGoal{6.5, 1.5, 0.0};

std::unique_ptr<sim::Simulation> small_simulation(bool with_robot) {
  sim::World world;
  world.map = sim::walled_grid(8.0, 6.0, 0.1);
  world.props = {{4.0, 4.5, 0.6, 0.4, 0.8, 0x336699, 0.3}};
  world.landmarks = {{"goal", 7.0, 5.0, 0.3, 0xf2c12e}};
  world.obstacles = sim::with_props_blocked(world.map, world.props);
  world.avatar.pose = {6.0, 0.8, std::numbers::pi / 2.0};
  sim::RobotSetup setup;
  if (with_robot) {
    sim::Robot robot;
    robot.pose = {1.5, 1.5, 0.0};
    robot.estimate = robot.pose;
    world.robot = robot;
    setup.mission.kind = sim::MissionSpec::Kind::GoTo;
    setup.mission.waypoints = {kGoal};
    setup.mission.waypoint_names = {""};
  }
  sim::CrowdSpec crowd;
  crowd.count = 2;
  crowd.seed = 3;
  auto simulation = std::make_unique<sim::Simulation>(sim::SimulationParams{}, std::move(world), crowd, setup);
  simulation->apply_key(0x77, true);  // 'w': the avatar walks forward
  return simulation;
}

// Everything the sampler yields over tick 0 and kTicks steps, with the tick each sample was taken at.
struct Run {
  std::vector<ros::RosMessage> messages;
  std::vector<std::uint64_t> ticks;        // per message
  std::uint64_t command_changes = 0;      // ticks at which DriveCommand::sequence differed from the tick before
  std::uint64_t scans = 0;                // RobotStack::scans() at the end
};

Run run(sim::Simulation& simulation) {
  ros::RosWorldSampler sampler({60, 30});
  Run out;
  std::uint64_t sequence = 0;
  for (int tick = 0; tick <= kTicks; ++tick) {
    if (tick > 0) simulation.step();
    const std::size_t before = out.messages.size();
    sampler.sample(simulation.world(), simulation.robot_stack(), out.messages);
    out.ticks.resize(out.messages.size(), simulation.world().tick);
    // Within one tick the messages come in table order.
    for (std::size_t i = before + 1; i < out.messages.size(); ++i) {
      CHECK(out.messages[i - 1].topic < out.messages[i].topic);
    }
    if (const auto* stack = simulation.robot_stack()) {
      if (stack->last_command().sequence != sequence) ++out.command_changes;
      sequence = stack->last_command().sequence;
      out.scans = stack->scans();
    }
  }
  return out;
}

std::map<std::string, int> counts(const Run& r) {
  std::map<std::string, int> out;
  for (const auto& m : r.messages) ++out[m.topic->name];
  return out;
}

template <typename T>
std::vector<const T*> of_type(const Run& r) {
  std::vector<const T*> out;
  for (const auto& m : r.messages) {
    if (const T* p = std::get_if<T>(&m.payload)) out.push_back(p);
  }
  return out;
}

double yaw_of(const ros::Quaternion& q) { return 2.0 * std::atan2(q.z, q.w); }

}  // namespace

TEST_CASE("ros msgs: sim time is tick * 1e9 / tick_hz ns, exactly", "[ros]") {
  CHECK(ros::tick_time_ns(0, 60) == 0);
  CHECK(ros::tick_time_ns(1, 60) == 16'666'666);
  CHECK(ros::tick_time_ns(3, 60) == 50'000'000);
  CHECK(ros::tick_time_ns(60, 60) == 1'000'000'000);
  CHECK(ros::tick_time_ns(60ull * 86'400 * 365 + 1, 60) == 86'400ull * 365 * 1'000'000'000 + 16'666'666);
  CHECK(ros::time_from_ns(1'500'000'001).sec == 1);
  CHECK(ros::time_from_ns(1'500'000'001).nanosec == 500'000'001u);
}

TEST_CASE("ros msgs: the sampler refuses a pose rate that does not divide the tick rate", "[ros]") {
  CHECK_THROWS_AS(ros::RosWorldSampler({60, 25}), std::invalid_argument);
  CHECK_THROWS_AS(ros::RosWorldSampler({60, 0}), std::invalid_argument);
  CHECK_THROWS_AS(ros::RosWorldSampler({0, 30}), std::invalid_argument);
  CHECK_NOTHROW(ros::RosWorldSampler({60, 60}));
}

TEST_CASE("ros msgs: per-topic counts over two seconds with a robot", "[ros]") {
  auto simulation = small_simulation(true);
  const Run r = run(*simulation);
  const auto n = counts(r);
  CHECK(n.at("/clock") == kTicks + 1);
  CHECK(n.at("/tf") == kTicks / 2 + 1);  // ticks 0, 2, ..., 120
  CHECK(n.at("/odom") == kTicks / 2 + 1);
  CHECK(n.at("/people") == kTicks / 2 + 1);
  CHECK(n.at("/map") == 1);
  CHECK(n.at("/scene_markers") == 1);
  CHECK(n.at("/goal_pose") == 1);
  // One /scan per sweep (10 Hz: about 20) and one /cmd_vel per command the wheels were given.
  CHECK(r.scans >= 19);
  CHECK(n.at("/scan") == static_cast<int>(r.scans));
  CHECK(r.command_changes > 0);
  CHECK(n.at("/cmd_vel") == static_cast<int>(r.command_changes));
  CHECK(n.at("/plan") >= 1);
  CHECK(n.count("/events") == 0);

  // Each message's time is its tick's exact time; /clock says the same.
  for (std::size_t i = 0; i < r.messages.size(); ++i) {
    CHECK(r.messages[i].time_ns == ros::tick_time_ns(r.ticks[i], 60));
    if (const auto* clock = std::get_if<ros::Clock>(&r.messages[i].payload)) {
      CHECK(clock->clock.sec == static_cast<std::int32_t>(r.ticks[i] / 60));
      CHECK(clock->clock.nanosec == static_cast<std::uint32_t>(r.messages[i].time_ns % 1'000'000'000));
    }
  }
  // The latched ones went out at tick 0.
  for (std::size_t i = 0; i < r.messages.size(); ++i) {
    if (r.messages[i].topic->name == "/map" || r.messages[i].topic->name == "/scene_markers") CHECK(r.ticks[i] == 0);
  }
}

TEST_CASE("ros msgs: /tf composes map->odom->base_link to the robot's estimate, and names every body", "[ros]") {
  auto simulation = small_simulation(true);
  ros::RosWorldSampler sampler({60, 30});
  std::vector<ros::RosMessage> out;
  for (int i = 0; i < 90; ++i) simulation->step();  // even: a pose tick; the robot has moved and localized
  sampler.sample(simulation->world(), simulation->robot_stack(), out);
  const ros::TFMessage* tf = nullptr;
  for (const auto& m : out) {
    if (m.topic->name == "/tf") tf = &std::get<ros::TFMessage>(m.payload);
  }
  REQUIRE(tf);
  std::vector<std::string> children;
  for (const auto& t : tf->transforms) {
    children.push_back(t.header.frame_id + "->" + t.child_frame_id);
    CHECK(t.transform.translation.z == 0.0);
    CHECK(t.header.stamp.sec == 1);
    CHECK(t.header.stamp.nanosec == 500'000'000u);
  }
  CHECK(children == std::vector<std::string>{"map->odom", "odom->base_link", "map->robot_truth", "map->avatar",
                                             "map->person_1", "map->person_2"});
  // map->odom o odom->base_link = the estimate.
  const auto& mo = tf->transforms[0].transform;
  const auto& ob = tf->transforms[1].transform;
  const double a = yaw_of(mo.rotation);
  const double x = mo.translation.x + std::cos(a) * ob.translation.x - std::sin(a) * ob.translation.y;
  const double y = mo.translation.y + std::sin(a) * ob.translation.x + std::cos(a) * ob.translation.y;
  const sim::Pose2& estimate = simulation->world().robot->estimate;
  CHECK(x == Approx(estimate.x).margin(1e-9));
  CHECK(y == Approx(estimate.y).margin(1e-9));
  CHECK(std::remainder(a + yaw_of(ob.rotation) - estimate.yaw, 2.0 * std::numbers::pi) == Approx(0.0).margin(1e-9));
  // odom->base_link is the wheel odometry; map->robot_truth the true pose.
  CHECK(ob.translation.x == simulation->robot_stack()->odometry_pose().x);
  CHECK(tf->transforms[2].transform.translation.x == simulation->world().robot->pose.x);
  CHECK(tf->transforms[3].transform.rotation.z == Approx(std::sin(std::numbers::pi / 4.0)));
}

TEST_CASE("ros msgs: the sampled messages carry the world's values", "[ros]") {
  auto simulation = small_simulation(true);
  const Run r = run(*simulation);
  const sim::World& world = simulation->world();

  // /map: the obstacle grid, 100 where blocked, from the bottom row.
  const auto maps = of_type<ros::OccupancyGrid>(r);
  REQUIRE(maps.size() == 1);
  const ros::OccupancyGrid& map = *maps[0];
  CHECK(map.header.frame_id == "map");
  CHECK(map.info.width == static_cast<std::uint32_t>(world.obstacles.width));
  CHECK(map.info.height == static_cast<std::uint32_t>(world.obstacles.height));
  CHECK(map.info.resolution == 0.1f);
  REQUIRE(map.data.size() == world.obstacles.occupied.size());
  for (std::size_t i = 0; i < map.data.size(); ++i) CHECK(map.data[i] == (world.obstacles.occupied[i] ? 100 : 0));

  // /scene_markers: the crate as a cube standing on the floor, the landmark as a flat disc.
  const auto markers = of_type<ros::MarkerArray>(r);
  REQUIRE(markers.size() == 1);
  REQUIRE(markers[0]->markers.size() == 2);
  const ros::Marker& cube = markers[0]->markers[0];
  CHECK(cube.ns == "props");
  CHECK(cube.type == ros::Marker::kCube);
  CHECK(cube.pose.position.z == 0.4);
  CHECK(cube.scale.x == 0.6);
  CHECK(cube.scale.z == 0.8);
  CHECK(cube.color.r == 0x33 / 255.0f);
  CHECK(cube.color.a == 1.0f);
  CHECK(yaw_of(cube.pose.orientation) == Approx(0.3));
  const ros::Marker& disc = markers[0]->markers[1];
  CHECK(disc.ns == "landmarks");
  CHECK(disc.type == ros::Marker::kCylinder);
  CHECK(disc.scale.x == 0.6);
  CHECK(disc.pose.position.x == 7.0);

  // /scan: the robot's lidar as configured.
  const auto scans = of_type<ros::LaserScan>(r);
  REQUIRE_FALSE(scans.empty());
  const ros::LaserScan& scan = *scans.back();
  const auto& lidar = simulation->robot_stack()->params().lidar;
  CHECK(scan.header.frame_id == "base_link");
  CHECK(scan.ranges.size() == static_cast<std::size_t>(lidar.beams));
  CHECK(scan.angle_max == Approx(scan.angle_min + static_cast<float>(lidar.beams - 1) * scan.angle_increment));
  CHECK(scan.scan_time == static_cast<float>(1.0 / lidar.rate_hz));
  CHECK(scan.range_max == static_cast<float>(lidar.range_max));
  const auto& sweep = simulation->robot_stack()->last_scan();
  CHECK(scan.header.stamp.sec == static_cast<std::int32_t>(sweep.time));
  CHECK(ros::tick_time_ns(static_cast<std::uint64_t>(std::llround(sweep.time * 60)), 60) % 1'000'000'000 ==
        scan.header.stamp.nanosec);

  // /people: both walkers and the avatar, walking forward (+y) at its speed.
  const auto people = of_type<ros::People>(r);
  REQUIRE_FALSE(people.empty());
  const ros::People& last = *people.back();
  REQUIRE(last.people.size() == 3);
  CHECK(last.people[0].name == "person_1");
  CHECK(last.people[0].position.x == world.people[0].pose.x);
  CHECK(last.people[0].velocity.y == world.people[0].velocity.y());
  CHECK(last.people[2].name == "avatar");
  CHECK(world.avatar.speed > 0.5);
  CHECK(last.people[2].velocity.y == Approx(world.avatar.speed));
  CHECK(last.people[2].velocity.x == Approx(0.0).margin(1e-12));
  CHECK(last.people[2].reliability == 1.0);

  // /goal_pose: the mission's goal; /plan: a path in the map frame from near the robot to the goal.
  const auto goals = of_type<ros::PoseStamped>(r);
  REQUIRE(goals.size() == 1);
  CHECK(goals[0]->header.frame_id == "map");
  CHECK(goals[0]->pose.position.x == kGoal.x);
  const auto plans = of_type<ros::Path>(r);
  REQUIRE_FALSE(plans.empty());
  REQUIRE(plans[0]->poses.size() >= 2);
  CHECK(plans[0]->poses.back().pose.position.x == Approx(kGoal.x).margin(0.1));
  // Each pose faces the next one.
  const auto& poses = plans[0]->poses;
  for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
    const double dx = poses[i + 1].pose.position.x - poses[i].pose.position.x;
    const double dy = poses[i + 1].pose.position.y - poses[i].pose.position.y;
    if (dx == 0.0 && dy == 0.0) continue;
    CHECK(std::remainder(yaw_of(poses[i].pose.orientation) - std::atan2(dy, dx), 2.0 * std::numbers::pi) ==
          Approx(0.0).margin(1e-9));
  }

  // /cmd_vel: the last one is the command the wheels were last given.
  const auto twists = of_type<ros::Twist>(r);
  REQUIRE_FALSE(twists.empty());
  CHECK(twists.back()->linear.x == simulation->robot_stack()->last_command().v);
  CHECK(twists.back()->angular.z == simulation->robot_stack()->last_command().w);
  // /odom: the wheels' speed in base_link.
  const auto odoms = of_type<ros::Odometry>(r);
  CHECK(odoms.back()->child_frame_id == "base_link");
  CHECK(odoms.back()->twist.twist.linear.x == simulation->robot_stack()->wheel_v());
}

TEST_CASE("ros msgs: without a robot only the clock, /tf of people, /people and the scene go out", "[ros]") {
  auto simulation = small_simulation(false);
  const Run r = run(*simulation);
  const auto n = counts(r);
  CHECK(n == std::map<std::string, int>{{"/clock", kTicks + 1},
                                        {"/tf", kTicks / 2 + 1},
                                        {"/map", 1},
                                        {"/scene_markers", 1},
                                        {"/people", kTicks / 2 + 1}});
  const auto tfs = of_type<ros::TFMessage>(r);
  REQUIRE(tfs.back()->transforms.size() == 3);
  CHECK(tfs.back()->transforms[0].child_frame_id == "avatar");
}

TEST_CASE("ros msgs: an event goes out as /events with its line and time", "[ros]") {
  ros::RosWorldSampler sampler({60, 30});
  std::vector<ros::RosMessage> out;
  sampler.add_event(123, R"({"t":0.1,"type":"start"})", out);
  REQUIRE(out.size() == 1);
  CHECK(out[0].topic->name == "/events");
  CHECK(out[0].time_ns == 123);
  CHECK(std::get<ros::String>(out[0].payload).data == R"({"t":0.1,"type":"start"})");
  CHECK(ros::ros_type_name(out[0].payload) == "std_msgs/msg/String");
}
