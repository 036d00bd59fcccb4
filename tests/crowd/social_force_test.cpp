// SPDX-License-Identifier: GPL-2.0-or-later
// The social force terms one at a time, with numbers worked out by hand from the papers' formulas.
#include <catch2/catch.hpp>

#include <cmath>

#include "crowd/social_force.hpp"

using namespace rfbsim::sim;

TEST_CASE("the goal force relaxes the velocity toward the desired one in tau") {
  const SocialForceParams params;
  const Eigen::Vector2d f = goal_force({0.5, 0.0}, {0.0, 1.0}, 1.34, params);
  CHECK(f.x() == Approx(-1.0));   // (0 - 0.5) / 0.5
  CHECK(f.y() == Approx(2.68));   // (1.34 - 0) / 0.5
}

TEST_CASE("speed is capped at 1.3 times the desired speed, direction kept") {
  const SocialForceParams params;
  const Eigen::Vector2d v = cap_speed({3.0, 4.0}, 1.0, params);
  CHECK(v.norm() == Approx(1.3));
  CHECK(v.x() / v.y() == Approx(0.75));
  CHECK(cap_speed({0.3, 0.4}, 1.0, params) == Eigen::Vector2d(0.3, 0.4));
}

TEST_CASE("Moussaid: a person walking at someone standing ahead brakes and steps to its right") {
  const SocialForceParams params;
  // Self at the origin walking +x at 1 m/s, the other standing 2 m ahead: D = 2 (1, 0) + (1, 0), |D| = 3,
  // t = (1, 0), theta = 0, B = 0.35 * 3 = 1.05; both terms are 5.1 exp(-2 / 1.05); "right" is -y.
  const Eigen::Vector2d f = pedestrian_force({{0, 0}, {1, 0}}, {1, 0}, {{2, 0}, {0, 0}}, params);
  const double k = 5.1 * std::exp(-2.0 / 1.05);
  CHECK(f.x() == Approx(-k));
  CHECK(f.y() == Approx(-k));
}

TEST_CASE("Moussaid: someone ahead on the left pushes to the right, and the mirror image") {
  const SocialForceParams params;
  const Eigen::Vector2d left = pedestrian_force({{0, 0}, {1, 0}}, {1, 0}, {{2, 0.3}, {0, 0}}, params);
  const Eigen::Vector2d right = pedestrian_force({{0, 0}, {1, 0}}, {1, 0}, {{2, -0.3}, {0, 0}}, params);
  CHECK(left.y() < 0.0);
  CHECK(right.y() > 0.0);
  CHECK(left.x() == Approx(right.x()));
  CHECK(left.y() == Approx(-right.y()));
  // Far away, nothing: beyond the interaction range the force is exactly zero.
  CHECK(pedestrian_force({{0, 0}, {1, 0}}, {1, 0}, {{9, 0}, {0, 0}}, params) == Eigen::Vector2d::Zero());
}

TEST_CASE("Helbing-Molnar: a standing person repels with V0 / sigma exp(-d / sigma), half behind") {
  SocialForceParams params;
  params.model = PedestrianModel::HelbingMolnar1995;
  // The other stands still, so the ellipse is a circle: b = |r| = 1.
  const double expected = 2.1 / 0.3 * std::exp(-1.0 / 0.3);
  const Eigen::Vector2d ahead = pedestrian_force({{0, 0}, {1, 0}}, {1, 0}, {{1, 0}, {0, 0}}, params);
  CHECK(ahead.x() == Approx(-expected));
  CHECK(ahead.y() == Approx(0.0).margin(1e-12));
  // Behind (180 deg from the walking direction, outside the 100 deg half-angle): weight 0.5.
  const Eigen::Vector2d behind = pedestrian_force({{0, 0}, {1, 0}}, {1, 0}, {{-1, 0}, {0, 0}}, params);
  CHECK(behind.x() == Approx(0.5 * expected));
}

TEST_CASE("Helbing-Molnar: someone walking toward me repels more than someone standing") {
  SocialForceParams params;
  params.model = PedestrianModel::HelbingMolnar1995;
  // The other 3 m ahead walking at me at 1 m/s: its next step s = 2 m shrinks b below 3 m.
  const Eigen::Vector2d moving = pedestrian_force({{0, 0}, {0, 0}}, {1, 0}, {{3, 0}, {-1, 0}}, params);
  const Eigen::Vector2d standing = pedestrian_force({{0, 0}, {0, 0}}, {1, 0}, {{3, 0}, {0, 0}}, params);
  // r = (-3, 0), s = (-2, 0): |r| + |r - s| = 4, b = sqrt(16 - 4) / 2 = sqrt(3); db/dr = 4/(4b) * (-2, 0).
  const double b = std::sqrt(3.0);
  CHECK(moving.x() == Approx(-2.1 / 0.3 * std::exp(-b / 0.3) * 2.0 / b));
  CHECK(std::abs(moving.x()) > std::abs(standing.x()));
}

TEST_CASE("the wall force is U0 / R exp(-d / R) away from the nearest wall") {
  // A 1 m grid: walls left and right, free columns 1..7; at x = 2.5 the left wall's surface is ~1.5 m away.
  const GridMap map = grid_from_text({"#########", "#.......#", "#.......#", "#.......#", "#########"}, 1.0);
  const DistanceField field(map);
  const SocialForceParams params;
  const Eigen::Vector2d f = wall_force({1.5, 2.5}, field, params);
  const double d = field.at(1.5, 2.5);
  CHECK(d == Approx(0.5).margin(0.01));
  CHECK(f.norm() == Approx(10.0 / 0.2 * std::exp(-d / 0.2)));
  CHECK(f.x() > 0.0);  // pushed right, away from the left wall
  // In the middle the field is flat across: no push.
  CHECK(wall_force({4.5, 2.5}, field, params).norm() == Approx(0.0).margin(1e-9));
}
