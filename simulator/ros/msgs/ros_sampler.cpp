// SPDX-License-Identifier: GPL-2.0-or-later
// RosWorldSampler (declared in ros_topics.hpp): the world, read after a tick, as the ROS messages due then.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "ros/msgs/ros_topics.hpp"

namespace rfbsim::ros {

namespace {

// The topics by their place in ros_topics(), the order messages are appended in.
enum TopicIndex { kClock, kTf, kOdom, kScan, kMap, kSceneMarkers, kCmdVel, kPeople, kPlan, kGoalPose, kEvents };

const TopicSpec* topic(TopicIndex index) { return &ros_topics()[static_cast<std::size_t>(index)]; }

// A turn about z by `yaw` (the floor plane's only rotation).
Quaternion yaw_quaternion(double yaw) { return {0.0, 0.0, std::sin(yaw / 2.0), std::cos(yaw / 2.0)}; }

Pose pose_of(double x, double y, double yaw) { return {{x, y, 0.0}, yaw_quaternion(yaw)}; }
Pose pose_of(const sim::Pose2& p) { return pose_of(p.x, p.y, p.yaw); }

TransformStamped transform(const Time& stamp, const char* parent, std::string child, const sim::Pose2& p) {
  return {{stamp, parent}, std::move(child), {{p.x, p.y, 0.0}, yaw_quaternion(p.yaw)}};
}

// map->odom from the robot's belief: estimate = (map->odom) o (odom->base_link), so
// map->odom = estimate o odometry^-1; in the plane: yaw e - o, and the estimate's position less the odometry
// position turned by that yaw.
sim::Pose2 map_to_odom(const sim::Pose2& estimate, const sim::Pose2& odometry) {
  const double yaw = estimate.yaw - odometry.yaw;
  const double c = std::cos(yaw);
  const double s = std::sin(yaw);
  return {estimate.x - (c * odometry.x - s * odometry.y), estimate.y - (s * odometry.x + c * odometry.y), yaw};
}

ColorRGBA colour(std::uint32_t rgb) {
  return {static_cast<float>((rgb >> 16) & 0xffu) / 255.0f, static_cast<float>((rgb >> 8) & 0xffu) / 255.0f,
          static_cast<float>(rgb & 0xffu) / 255.0f, 1.0f};
}

TFMessage tf_message(const sim::World& world, const sim::RobotStack* robot, const Time& stamp) {
  TFMessage tf;
  tf.transforms.reserve(5 + world.people.size());
  if (robot && world.robot) {
    const sim::Pose2& odometry = robot->odometry_pose();
    tf.transforms.push_back(transform(stamp, "map", "odom", map_to_odom(world.robot->estimate, odometry)));
    tf.transforms.push_back(transform(stamp, "odom", "base_link", odometry));
    tf.transforms.push_back(transform(stamp, "map", "robot_truth", world.robot->pose));
  }
  tf.transforms.push_back(transform(stamp, "map", "avatar", world.avatar.pose));
  for (const sim::Person& person : world.people) {
    tf.transforms.push_back(transform(stamp, "map", "person_" + std::to_string(person.id), person.pose));
  }
  return tf;
}

Odometry odometry_message(const sim::RobotStack& robot, const Time& stamp) {
  Odometry odom;
  odom.header = {stamp, "odom"};
  odom.child_frame_id = "base_link";
  odom.pose.pose = pose_of(robot.odometry_pose());
  odom.twist.twist.linear.x = robot.wheel_v();   // in base_link: forward
  odom.twist.twist.angular.z = robot.wheel_w();  // counter-clockwise
  return odom;
}

LaserScan scan_message(const sim::RobotStack& robot, int tick_hz) {
  const sim::LaserScan& sweep = robot.last_scan();
  LaserScan scan;
  // The sweep was cast at a tick; its stamp is that tick's exact time.
  const auto sweep_tick = static_cast<std::uint64_t>(std::llround(std::max(0.0, sweep.time) * tick_hz));
  scan.header = {time_from_ns(tick_time_ns(sweep_tick, tick_hz)), "base_link"};
  const std::size_t n = sweep.ranges.size();
  scan.angle_min = static_cast<float>(sweep.angle_min);
  scan.angle_increment = static_cast<float>(sweep.angle_increment);
  scan.angle_max = static_cast<float>(sweep.angle_min + static_cast<double>(n > 0 ? n - 1 : 0) * sweep.angle_increment);
  scan.time_increment = 0.0f;  // the simulated sweep is instantaneous
  const double rate = robot.params().lidar.rate_hz;
  scan.scan_time = rate > 0.0 ? static_cast<float>(1.0 / rate) : 0.0f;
  scan.range_min = static_cast<float>(sweep.range_min);
  scan.range_max = static_cast<float>(sweep.range_max);
  scan.ranges = sweep.ranges;
  return scan;
}

OccupancyGrid map_message(const sim::GridMap& grid, const Time& stamp) {
  OccupancyGrid map;
  map.header = {stamp, "map"};
  map.info.map_load_time = stamp;
  map.info.resolution = static_cast<float>(grid.resolution);
  map.info.width = static_cast<std::uint32_t>(std::max(grid.width, 0));
  map.info.height = static_cast<std::uint32_t>(std::max(grid.height, 0));
  map.info.origin = pose_of(grid.origin_x, grid.origin_y, grid.origin_yaw);
  // GridMap is already row-major from the bottom row, as ROS wants; blocking cells (walls, props and unknown
  // space alike) read as occupied.
  map.data.reserve(grid.occupied.size());
  for (std::uint8_t cell : grid.occupied) map.data.push_back(cell ? std::int8_t{100} : std::int8_t{0});
  return map;
}

MarkerArray scene_markers(const sim::World& world, const Time& stamp) {
  MarkerArray array;
  std::int32_t id = 0;
  for (const sim::Prop& prop : world.props) {
    Marker box;
    box.header = {stamp, "map"};
    box.ns = "props";
    box.id = id++;
    box.type = Marker::kCube;
    box.pose = pose_of(prop.x, prop.y, prop.yaw);
    box.pose.position.z = prop.height / 2.0;  // standing on the floor
    box.scale = {prop.size_x, prop.size_y, prop.height};
    box.color = colour(prop.rgb);
    array.markers.push_back(std::move(box));
  }
  // Landmarks are painted on the floor: flat discs.
  constexpr double kDiscHeight = 0.02;
  id = 0;
  for (const sim::Landmark& landmark : world.landmarks) {
    Marker disc;
    disc.header = {stamp, "map"};
    disc.ns = "landmarks";
    disc.id = id++;
    disc.type = Marker::kCylinder;
    disc.pose = pose_of(landmark.x, landmark.y, 0.0);
    disc.pose.position.z = kDiscHeight / 2.0;
    disc.scale = {2.0 * landmark.radius, 2.0 * landmark.radius, kDiscHeight};
    disc.color = colour(landmark.rgb);
    array.markers.push_back(std::move(disc));
  }
  return array;
}

Person person_entry(std::string name, double x, double y, double vx, double vy) {
  Person person;
  person.name = std::move(name);
  person.position = {x, y, 0.0};
  person.velocity = {vx, vy, 0.0};
  person.reliability = 1.0;  // simulated people are known exactly
  return person;
}

People people_message(const sim::World& world, const Time& stamp) {
  People people;
  people.header = {stamp, "map"};
  people.people.reserve(world.people.size() + 1);
  for (const sim::Person& p : world.people) {
    people.people.push_back(person_entry("person_" + std::to_string(p.id), p.pose.x, p.pose.y, p.velocity.x(),
                                         p.velocity.y()));
  }
  const sim::Avatar& avatar = world.avatar;
  people.people.push_back(person_entry("avatar", avatar.pose.x, avatar.pose.y,
                                       avatar.speed * std::cos(avatar.pose.yaw),
                                       avatar.speed * std::sin(avatar.pose.yaw)));
  return people;
}

Path path_message(const std::vector<Eigen::Vector2d>& points, const Time& stamp) {
  Path path;
  path.header = {stamp, "map"};
  path.poses.reserve(points.size());
  double yaw = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    // Each pose faces the next point; the last keeps the heading of the segment into it.
    if (i + 1 < points.size()) {
      const Eigen::Vector2d step = points[i + 1] - points[i];
      if (step.squaredNorm() > 0.0) yaw = std::atan2(step.y(), step.x());
    }
    path.poses.push_back({{stamp, "map"}, pose_of(points[i].x(), points[i].y(), yaw)});
  }
  return path;
}

bool same_pose(const sim::Pose2& a, const sim::Pose2& b) { return a.x == b.x && a.y == b.y && a.yaw == b.yaw; }

}  // namespace

RosWorldSampler::RosWorldSampler(RosSamplerOptions options) : options_(options) {
  if (options.tick_hz <= 0 || options.pose_hz <= 0 || options.tick_hz % options.pose_hz != 0) {
    throw std::invalid_argument("ROS sampler: pose_hz (" + std::to_string(options.pose_hz) +
                                ") must be positive and divide tick_hz (" + std::to_string(options.tick_hz) + ")");
  }
  pose_every_ = static_cast<std::uint64_t>(options.tick_hz / options.pose_hz);
}

void RosWorldSampler::sample(const sim::World& world, const sim::RobotStack* robot, std::vector<RosMessage>& out) {
  const std::uint64_t now = tick_time_ns(world.tick, options_.tick_hz);
  const Time stamp = time_from_ns(now);
  const bool pose_tick = world.tick % pose_every_ == 0;
  auto emit = [&](TopicIndex index, RosPayload payload) { out.push_back({topic(index), now, std::move(payload)}); };

  emit(kClock, Clock{stamp});
  if (pose_tick) emit(kTf, tf_message(world, robot, stamp));
  if (pose_tick && robot) emit(kOdom, odometry_message(*robot, stamp));
  if (robot && robot->scans() != scans_seen_) {
    scans_seen_ = robot->scans();
    emit(kScan, scan_message(*robot, options_.tick_hz));
  }
  if (!scene_sent_) {
    scene_sent_ = true;
    emit(kMap, map_message(world.obstacles, stamp));
    emit(kSceneMarkers, scene_markers(world, stamp));
  }
  if (robot && robot->last_command().sequence != command_seen_) {
    command_seen_ = robot->last_command().sequence;
    Twist command;
    command.linear.x = robot->last_command().v;
    command.angular.z = robot->last_command().w;
    emit(kCmdVel, command);
  }
  if (pose_tick) emit(kPeople, people_message(world, stamp));
  if (robot && world.robot && world.robot->nav.global_path != path_seen_) {
    path_seen_ = world.robot->nav.global_path;
    emit(kPlan, path_message(path_seen_, stamp));
  }
  if (robot && robot->mission_goal() && !(goal_seen_ && same_pose(*goal_seen_, *robot->mission_goal()))) {
    goal_seen_ = robot->mission_goal();
    emit(kGoalPose, PoseStamped{{stamp, "map"}, pose_of(*goal_seen_)});
  }
}

void RosWorldSampler::add_event(std::uint64_t time_ns, std::string json_line, std::vector<RosMessage>& out) {
  out.push_back({topic(kEvents), time_ns, String{std::move(json_line)}});
}

}  // namespace rfbsim::ros
