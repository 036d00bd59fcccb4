// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "avatar/avatar_motion.hpp"

using namespace rfbsim::sim;

namespace {
// A 10 m x 10 m room of 1 m cells with walls all round, origin at its lower-left corner.
GridMap room() {
  GridMap map = grid_from_text({"##########", "#........#", "#........#", "#........#", "#........#",
                                "#........#", "#........#", "#........#", "#........#", "##########"},
                               1.0);
  return map;
}
void run(const AvatarParams& p, const ControlState& c, const GridMap& m, Avatar& a, int steps) {
  for (int i = 0; i < steps; ++i) step_avatar(p, c, m, 0.01, a);
}
}  // namespace

TEST_CASE("holding forward accelerates to walking speed along the heading") {
  AvatarParams params;
  Avatar avatar;
  avatar.pose = {5.0, 2.0, std::numbers::pi / 2};
  ControlState forward;
  forward.forward = true;
  step_avatar(params, forward, room(), 0.01, avatar);
  CHECK(avatar.speed == Approx(0.06));  // 6 m/s^2 for 10 ms
  run(params, forward, room(), avatar, 99);
  CHECK(avatar.speed == Approx(1.3));
  CHECK(avatar.pose.x == Approx(5.0).margin(1e-9));
  // 1 s: accelerating for 1.3/6 s covers 0.1408 m, then 1.3 m/s for the rest.
  const double t_acc = 1.3 / 6.0;
  CHECK(avatar.pose.y - 2.0 == Approx(0.5 * 6.0 * t_acc * t_acc + 1.3 * (1.0 - t_acc)).epsilon(0.01));
  CHECK(avatar.distance_walked == Approx(avatar.pose.y - 2.0));
}

TEST_CASE("turning changes yaw at the turn rate and wraps to -pi to pi") {
  AvatarParams params;
  Avatar avatar;
  ControlState left;
  left.turn_left = true;
  run(params, left, room(), avatar, 100);
  CHECK(avatar.pose.yaw == Approx(1.8));
  run(params, left, room(), avatar, 100);
  CHECK(avatar.pose.yaw == Approx(3.6 - 2 * std::numbers::pi));
  ControlState right;
  right.turn_right = true;
  run(params, right, room(), avatar, 200);
  CHECK(avatar.pose.yaw == Approx(0.0).margin(1e-9));
}

TEST_CASE("backward is slower - and opposite keys cancel") {
  AvatarParams params;
  Avatar avatar;
  avatar.pose = {5.0, 5.0, 0.0};
  ControlState back;
  back.backward = true;
  run(params, back, room(), avatar, 100);
  CHECK(avatar.speed == Approx(-0.7));
  CHECK(avatar.pose.x < 5.0);
  ControlState both;
  both.forward = both.backward = true;
  run(params, both, room(), avatar, 100);
  CHECK(avatar.speed == Approx(0.0).margin(1e-12));
}

TEST_CASE("walls stop the avatar and it slides along them") {
  AvatarParams params;
  Avatar avatar;
  avatar.pose = {5.0, 5.0, std::numbers::pi / 4};  // diagonally toward the top-right corner
  ControlState forward;
  forward.forward = true;
  run(params, forward, room(), avatar, 1500);
  // The inner free area spans 1..9 m; the body (radius 0.3) stops 0.3 m short of the walls.
  CHECK(avatar.pose.x <= 9.0 - params.radius);
  CHECK(avatar.pose.y <= 9.0 - params.radius);
  CHECK(avatar.pose.x > 8.6);
  CHECK(avatar.pose.y > 8.6);
  CHECK_FALSE(room().disc_hits_wall(avatar.pose.x, avatar.pose.y, params.radius));
}

TEST_CASE("the gait advances with distance walked - not with time") {
  AvatarParams params;
  Avatar walking;
  walking.pose = {5.0, 2.0, std::numbers::pi / 2};
  ControlState forward;
  forward.forward = true;
  run(params, forward, room(), walking, 50);
  const double expected = std::fmod(walking.distance_walked / params.stride_length * 2 * std::numbers::pi,
                                    2 * std::numbers::pi);
  CHECK(walking.gait_phase == Approx(expected));
  Avatar standing;
  run(params, ControlState{}, room(), standing, 50);
  CHECK(standing.gait_phase == 0.0);
}

TEST_CASE("the camera climbs within its limits") {
  CameraParams params;
  CameraRig camera;
  ControlState up;
  up.camera_up = true;
  step_camera(params, up, 1.0, camera);
  CHECK(camera.height == Approx(3.7));
  step_camera(params, up, 10.0, camera);
  CHECK(camera.height == Approx(params.max_height));
  ControlState down;
  down.camera_down = true;
  step_camera(params, down, 10.0, camera);
  CHECK(camera.height == Approx(params.min_height));
}
