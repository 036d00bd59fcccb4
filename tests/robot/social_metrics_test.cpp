// SPDX-License-Identifier: GPL-2.0-or-later
// social_metrics on hand-made series with exact answers: one robot, one or two people, a few samples.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "robot/social_metrics.hpp"

namespace sim = rfbsim::sim;

namespace {

constexpr double kPi = std::numbers::pi;

// A sample at time t: the robot at (x, 0) facing yaw with velocity (vx, 0); one person per (px, py, pvx).
struct P {
  double x, y, vx;
};
sim::SocialSample sample(double t, double x, double vx, std::vector<P> people, double yaw = 0.0) {
  sim::SocialSample s;
  s.time = t;
  s.robot = {x, 0.0, yaw};
  s.robot_velocity = {vx, 0.0};
  for (const P& p : people) s.people.push_back({{p.x, p.y}, {p.vx, 0.0}, 0.25});
  return s;
}

}  // namespace

TEST_CASE("social metrics: time to collision of two discs at constant velocity", "[social_metrics]") {
  // 2 m apart centre to centre, reach 0.5 m, closing at 1 m/s: they touch after 1.5 s.
  CHECK(sim::time_to_collision({2.0, 0.0}, {-1.0, 0.0}, 0.5) == Approx(1.5));
  // Already touching: 0. Moving apart or side by side: never.
  CHECK(sim::time_to_collision({0.4, 0.0}, {1.0, 0.0}, 0.5) == 0.0);
  CHECK(sim::time_to_collision({2.0, 0.0}, {1.0, 0.0}, 0.5) == sim::SocialMetrics::kNoTime);
  CHECK(sim::time_to_collision({2.0, 0.0}, {0.0, 0.0}, 0.5) == sim::SocialMetrics::kNoTime);
  // Passing 1 m to the side with a reach of 0.5 m: a miss.
  CHECK(sim::time_to_collision({2.0, 1.0}, {-1.0, 0.0}, 0.5) == sim::SocialMetrics::kNoTime);
  // Passing 0.3 m to the side: they touch when the along-track offset is sqrt(0.25 - 0.09) = 0.4 m.
  CHECK(sim::time_to_collision({2.0, 0.3}, {-1.0, 0.0}, 0.5) == Approx(1.6));
}

TEST_CASE("social metrics: the robot driving up to a standing person is a robot-caused intrusion", "[social_metrics]") {
  // The robot drives at 0.5 m/s from x = 0 toward a person standing at x = 2, and stops at x = 1.4
  // (0.6 m centre to centre), one sample every 0.2 s.
  std::vector<sim::SocialSample> series;
  for (int k = 0; k <= 7; ++k) series.push_back(sample(0.2 * k, 0.1 * k, k == 0 ? 0.0 : 0.5, {{2.0, 0.0, 0.0}}));
  for (int k = 8; k <= 12; ++k) series.push_back(sample(0.2 * k, 0.7, 0.0, {{2.0, 0.0, 0.0}}));
  // ... and then it moved on to 1.4 m in one step: the closest sample carries the velocity that took it there.
  series.push_back(sample(2.6, 1.4, 3.5, {{2.0, 0.0, 0.0}}));
  series.push_back(sample(2.8, 1.4, 0.0, {{2.0, 0.0, 0.0}}));
  const sim::SocialMetrics m = sim::social_metrics(series);
  CHECK(m.samples == 15);
  CHECK(m.duration == Approx(2.8));
  CHECK(m.path_length == Approx(1.4));
  CHECK(m.min_distance == Approx(0.6));
  CHECK(m.min_gap == Approx(0.6 - 0.41));
  CHECK(m.min_distance_robot_approaching == Approx(0.6));
  // Within 1.2 m only at x = 1.4: one episode, open at the end, the robot's doing; never within 0.45 m.
  CHECK(m.personal_intrusions == 1);
  CHECK(m.robot_personal_intrusions == 1);
  CHECK(m.robot_intrusion_share() == 1.0);
  CHECK(m.intimate_intrusions == 0);
  // Stopped: the first sample's interval (v = 0), five samples at x = 0.7 (1.0 s), and nothing after the last.
  CHECK(m.time_stopped == Approx(0.2 + 1.0));
  // TTC: at x = 0.7 the robot is stopped (no collision); at 0.6 m moving 3.5 m/s: (0.6 - 0.41) / 3.5 s.
  CHECK(m.min_ttc == Approx(0.19 / 3.5));
  CHECK(m.min_ttc_robot_approaching == Approx(0.19 / 3.5));
  // Straight toward the goal (the last position) with no turning: no irregularity.
  CHECK(m.path_irregularity == 0.0);
}

TEST_CASE("social metrics: a person walking up to a standing robot is not the robot's intrusion", "[social_metrics]") {
  // The robot stands at the origin; a person walks from x = 3 to x = 0.5 at 1 m/s and back out.
  std::vector<sim::SocialSample> series;
  double t = 0.0;
  for (double px = 3.0; px > 0.45; px -= 0.25, t += 0.25) series.push_back(sample(t, 0.0, 0.0, {{px, 0.0, -1.0}}));
  for (double px = 0.75; px <= 3.0; px += 0.25, t += 0.25) series.push_back(sample(t, 0.0, 0.0, {{px, 0.0, 1.0}}));
  const sim::SocialMetrics m = sim::social_metrics(series);
  CHECK(m.min_distance == Approx(0.5));
  CHECK(m.min_distance_robot_approaching == sim::SocialMetrics::kNoDistance);
  CHECK(m.personal_intrusions == 1);
  CHECK(m.robot_personal_intrusions == 0);
  CHECK(m.robot_intrusion_share() == 0.0);
  CHECK(m.min_ttc_robot_approaching == sim::SocialMetrics::kNoTime);
  // Closing at 1 m/s: the smallest TTC is at 0.5 m, with 0.5 - 0.41 m to go.
  CHECK(m.min_ttc == Approx((0.5 - 0.41) / 1.0));
  CHECK(m.time_stopped == Approx(series.back().time));
}

TEST_CASE("social metrics: episodes end only past the hysteresis, one per person", "[social_metrics]") {
  // Person A hovers at 1.19 / 1.22 / 1.19 m (inside the 0.05 m hysteresis: one episode), then leaves to 2 m,
  // then comes back to 1.0 m: two episodes. Person B never comes within 1.2 m.
  std::vector<sim::SocialSample> series;
  const double a[] = {2.0, 1.19, 1.22, 1.19, 2.0, 1.0, 2.0};
  for (int k = 0; k < 7; ++k) series.push_back(sample(k, 0.0, 0.0, {{a[k], 0.0, 0.0}, {0.0, 3.0, 0.0}}));
  const sim::SocialMetrics m = sim::social_metrics(series);
  CHECK(m.personal_intrusions == 2);
  CHECK(m.robot_personal_intrusions == 0);
  CHECK(m.min_distance == Approx(1.0));
}

TEST_CASE("social metrics: path irregularity is the turning beyond the straight line's", "[social_metrics]") {
  // Start facing +y with the goal along +x: the straight line needs a quarter turn. The robot turns a
  // quarter right, then weaves +0.3 and -0.3 rad: 0.6 rad more than needed over 2 m.
  std::vector<sim::SocialSample> series;
  series.push_back(sample(0.0, 0.0, 0.0, {}, kPi / 2.0));
  series.push_back(sample(1.0, 0.0, 0.0, {}, 0.0));
  series.push_back(sample(2.0, 1.0, 1.0, {}, 0.3));
  series.push_back(sample(3.0, 2.0, 1.0, {}, 0.0));
  sim::SocialMetricsParams params;
  params.goal = Eigen::Vector2d(2.0, 0.0);
  const sim::SocialMetrics m = sim::social_metrics(series, params);
  CHECK(m.rotation == Approx(kPi / 2.0 + 0.6));
  CHECK(m.path_irregularity == Approx(0.6));
  CHECK(m.path_irregularity_per_m == Approx(0.3));
  // Turning across +-pi counts the short way round.
  series[2].robot.yaw = kPi - 0.1;
  series[3].robot.yaw = -kPi + 0.1;
  const sim::SocialMetrics wrap = sim::social_metrics(series, params);
  CHECK(wrap.rotation == Approx(kPi / 2.0 + (kPi - 0.1) + 0.2));
}

TEST_CASE("social metrics: bad series and thresholds are refused with a reason", "[social_metrics]") {
  std::vector<sim::SocialSample> series{sample(0.0, 0.0, 0.0, {{1.0, 0.0, 0.0}}), sample(1.0, 0.0, 0.0, {})};
  CHECK_THROWS_WITH(sim::social_metrics(series), Catch::Contains("sample 1") && Catch::Contains("same people"));
  series[1] = sample(-1.0, 0.0, 0.0, {{1.0, 0.0, 0.0}});
  CHECK_THROWS_WITH(sim::social_metrics(series), Catch::Contains("time goes backwards"));
  series[1] = sample(1.0, std::nan(""), 0.0, {{1.0, 0.0, 0.0}});
  CHECK_THROWS_WITH(sim::social_metrics(series), Catch::Contains("not finite"));
  series[1] = sample(1.0, 0.0, 0.0, {{1.0, 0.0, 0.0}});
  sim::SocialMetricsParams params;
  params.personal_distance = 0.3;
  CHECK_THROWS_WITH(sim::social_metrics(series, params), Catch::Contains("personal_distance"));
  // Nothing to measure: zeros, no throw.
  const sim::SocialMetrics empty = sim::social_metrics({});
  CHECK(empty.samples == 0);
  CHECK(empty.min_distance == sim::SocialMetrics::kNoDistance);
}

TEST_CASE("social metrics: a world's sample lists the people and then the avatar", "[social_metrics]") {
  sim::World world;
  world.robot = sim::Robot{};
  world.robot->velocity = {0.2, 0.0};
  world.time = 4.5;
  sim::Person person;
  person.pose = {1.0, 2.0, 0.0};
  person.velocity = {0.5, 0.0};
  world.people.push_back(person);
  world.avatar.pose = {3.0, 0.0, kPi / 2.0};
  world.avatar.speed = 1.0;
  const sim::SocialSample s = sim::social_sample(world);
  CHECK(s.time == 4.5);
  REQUIRE(s.people.size() == 2);
  CHECK(s.people[0].position == Eigen::Vector2d(1.0, 2.0));
  CHECK(s.people[1].velocity.y() == Approx(1.0));
  CHECK(s.people[1].radius == world.avatar.radius);
  CHECK_THROWS(sim::social_sample(sim::World{}));
}
