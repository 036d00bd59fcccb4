// SPDX-License-Identifier: GPL-2.0-or-later
// Scene builder: people, props, landmarks and the robot are drawn where the world has them, inside their
// boxes, with per-person looks and gaits, deterministically and within the item budget; a scene compares equal to
// a new one until the world moves.
#include "render/scene_builder.hpp"

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "render/scene_parts.hpp"
#include "world/demo_world.hpp"

namespace {

using rfbsim::sim::DrawItem;
using rfbsim::sim::Shape;

// An open 10 x 10 m room at the origin with two people, a shelf, a desk, a landmark and the robot.
rfbsim::sim::World small_world() {
  rfbsim::sim::World world;
  std::vector<std::string> rows(20, std::string(20, '.'));
  world.map = rfbsim::sim::grid_from_text(
      {rows[0],  rows[1],  rows[2],  rows[3],  rows[4],  rows[5],  rows[6],  rows[7],  rows[8],  rows[9],
       rows[10], rows[11], rows[12], rows[13], rows[14], rows[15], rows[16], rows[17], rows[18], rows[19]},
      0.5);
  rfbsim::sim::Person a;
  a.id = 1;
  a.pose = {2.0, 2.0, 0.0};
  a.height = 1.6;
  a.velocity = {1.0, 0.0};
  a.gait_phase = 0.7;
  rfbsim::sim::Person b;
  b.id = 2;
  b.pose = {6.0, 3.0, 1.0};
  b.height = 1.9;
  b.rgb = 0x3a9e5a;
  world.people = {a, b};
  rfbsim::sim::Prop shelf{5.0, 7.0, 1.0, 3.0, 2.4, 0xb08850, 0.5, rfbsim::sim::PropKind::Shelf};
  rfbsim::sim::Prop desk{8.0, 8.0, 1.4, 0.7, 1.2, 0x8a6d4b, 0.0, rfbsim::sim::PropKind::Desk};
  world.props = {shelf, desk};
  world.landmarks.push_back({"goal", 1.0, 8.0, 0.3, 0xf2c12e});
  rfbsim::sim::Robot robot;
  robot.pose = {3.0, 5.0, 0.0};
  world.robot = robot;
  world.avatar.pose = {9.0, 1.0, 1.5};
  return world;
}

double horizontal_distance(const DrawItem& item, double x, double y) {
  const Eigen::Vector3f t = item.model.translation();
  return std::hypot(static_cast<double>(t.x()) - x, static_cast<double>(t.y()) - y);
}

// The highest item centre within `radius` of (x, y), or -1 if none.
double highest_centre_near(const std::vector<DrawItem>& items, double x, double y, double radius) {
  double top = -1.0;
  for (const DrawItem& item : items) {
    if (horizontal_distance(item, x, y) < radius)
      top = std::max(top, static_cast<double>(item.model.translation().z()));
  }
  return top;
}

// The eight corners of an item's unit cube in the world: a bound for every unit shape.
std::array<Eigen::Vector3f, 8> corners(const DrawItem& item) {
  std::array<Eigen::Vector3f, 8> out;
  for (int i = 0; i < 8; ++i) {
    out[static_cast<std::size_t>(i)] =
        item.model * Eigen::Vector3f((i & 1) ? 0.5f : -0.5f, (i & 2) ? 0.5f : -0.5f, (i & 4) ? 0.5f : -0.5f);
  }
  return out;
}

// Checks that every item lies inside the prop's turned box, and returns the highest point reached.
double check_inside(const std::vector<DrawItem>& items, const rfbsim::sim::Prop& prop) {
  double top = 0.0;
  for (const DrawItem& item : items) {
    for (const Eigen::Vector3f& p : corners(item)) {
      const double dx = static_cast<double>(p.x()) - prop.x, dy = static_cast<double>(p.y()) - prop.y;
      const double u = std::cos(prop.yaw) * dx + std::sin(prop.yaw) * dy;
      const double v = -std::sin(prop.yaw) * dx + std::cos(prop.yaw) * dy;
      CHECK(std::abs(u) <= prop.size_x / 2.0 + 1e-3);
      CHECK(std::abs(v) <= prop.size_y / 2.0 + 1e-3);
      CHECK(p.z() >= -1e-3f);
      CHECK(static_cast<double>(p.z()) <= prop.height + 1e-3);
      top = std::max(top, static_cast<double>(p.z()));
    }
  }
  return top;
}

// The items of a robot at (3, 5) facing 0.4 rad, with its head ahead and turned by head_yaw 0.9.
struct RobotHeadViews {
  std::vector<DrawItem> ahead;
  std::vector<DrawItem> turned;
};

RobotHeadViews robot_head_views() {
  rfbsim::sim::Robot robot;
  robot.pose = {3.0, 5.0, 0.4};
  RobotHeadViews views;
  rfbsim::sim::append_robot(views.ahead, robot);
  robot.head_yaw = 0.9;
  rfbsim::sim::append_robot(views.turned, robot);
  REQUIRE(views.ahead.size() == rfbsim::sim::kRobotBodyItems + rfbsim::sim::kRobotHeadItems + 2);
  REQUIRE(views.ahead.size() < 15);  // small enough to cost nothing per frame
  REQUIRE(views.turned.size() == views.ahead.size());
  return views;
}

}  // namespace

TEST_CASE("scene: each person's head is at their position and height, the taller one higher", "[scene]") {
  const auto world = small_world();
  const auto scene = rfbsim::sim::build_scene(world);
  const double a = highest_centre_near(scene.items, 2.0, 2.0, 0.3);
  const double b = highest_centre_near(scene.items, 6.0, 3.0, 0.3);
  // The hair's centre sits 7 cm under the top of the head (plus up to 3 cm of walking bob).
  CHECK(a == Approx(1.6 * 1.68 / 1.75).margin(0.03));
  CHECK(b == Approx(1.9 * 1.68 / 1.75).margin(1e-4));
  CHECK(b > a + 0.2);
}

TEST_CASE("scene: legs move between gait phases while walking and not while standing", "[scene]") {
  rfbsim::sim::Person p;
  p.velocity = {1.2, 0.0};
  std::vector<DrawItem> first, second;
  p.gait_phase = 0.3;
  rfbsim::sim::append_person(first, p);
  p.gait_phase = 1.9;
  rfbsim::sim::append_person(second, p);
  REQUIRE(first.size() == second.size());
  // Item 0 is the left leg, item 2 the right one.
  CHECK_FALSE(first[0].model.matrix().isApprox(second[0].model.matrix()));
  CHECK_FALSE(first[2].model.matrix().isApprox(second[2].model.matrix()));

  p.velocity = Eigen::Vector2d::Zero();
  first.clear();
  second.clear();
  p.gait_phase = 0.3;
  rfbsim::sim::append_person(first, p);
  p.gait_phase = 1.9;
  rfbsim::sim::append_person(second, p);
  for (std::size_t i = 0; i < first.size(); ++i) CHECK(first[i].model.matrix() == second[i].model.matrix());
}

TEST_CASE("scene: a faster walker swings wider", "[scene]") {
  const auto leg_tilt = [](double speed) {
    rfbsim::sim::Person p;
    p.velocity = {speed, 0.0};
    p.gait_phase = 1.5;
    std::vector<DrawItem> items;
    rfbsim::sim::append_person(items, p);
    // The leg's long axis leans forward by the swing angle.
    const Eigen::Vector3f axis = items[0].model.linear().col(2).normalized();
    return std::atan2(std::abs(axis.x()), axis.z());
  };
  CHECK(leg_tilt(0.0) == Approx(0.0).margin(1e-6));
  CHECK(leg_tilt(0.6) < leg_tilt(1.2));
  CHECK(leg_tilt(2.0) == Approx(leg_tilt(1.3)));  // the stride is capped at a brisk walk's
}

TEST_CASE("scene: a crowd is not cloned - looks differ by id and repeat for the same id", "[scene]") {
  const Eigen::Vector3f shirt{0.5f, 0.2f, 0.2f};
  int different = 0;
  for (int id = 2; id <= 10; ++id) {
    const auto a = rfbsim::sim::humanoid_look(1, shirt), b = rfbsim::sim::humanoid_look(id, shirt);
    if (a.trousers != b.trousers || a.skin != b.skin || a.hair != b.hair) ++different;
  }
  CHECK(different >= 8);
  CHECK(rfbsim::sim::humanoid_look(7, shirt).skin == rfbsim::sim::humanoid_look(7, shirt).skin);
  CHECK(rfbsim::sim::humanoid_look(7, shirt).shirt == shirt);
}

TEST_CASE("scene: every prop kind stays inside its turned box and reaches its height", "[scene]") {
  using rfbsim::sim::PropKind;
  for (const PropKind kind : {PropKind::Box, PropKind::Shelf, PropKind::Desk}) {
    for (const double yaw : {0.0, 0.5, -2.0}) {
      for (const auto& [sx, sy, h] :
           {std::array{1.0, 3.0, 2.4}, std::array{8.0, 1.0, 2.4}, std::array{1.4, 0.7, 1.2}}) {
        const rfbsim::sim::Prop prop{5.0, 7.0, sx, sy, h, 0xb08850, yaw, kind};
        std::vector<DrawItem> items;
        rfbsim::sim::append_prop(items, prop);
        INFO("kind " << static_cast<int>(kind) << " yaw " << yaw << " size " << sx << " x " << sy << " x " << h);
        REQUIRE_FALSE(items.empty());
        CHECK(check_inside(items, prop) == Approx(h).margin(1e-3));
      }
    }
  }
}

TEST_CASE("scene: a shelf is racking with goods on several levels, a desk has its top at 0.75 m", "[scene]") {
  const rfbsim::sim::Prop shelf{0.0, 0.0, 1.0, 8.0, 2.4, 0xb08850, 0.0, rfbsim::sim::PropKind::Shelf};
  std::vector<DrawItem> items;
  rfbsim::sim::append_prop(items, shelf);
  std::vector<float> tops;
  for (const DrawItem& item : items) tops.push_back(std::round(corners(item)[7].z() * 20.0f));
  std::sort(tops.begin(), tops.end());
  tops.erase(std::unique(tops.begin(), tops.end()), tops.end());
  CHECK(tops.size() >= 6);  // decks, goods of different heights, the uprights' tops
  CHECK(items.size() > 30);
  CHECK(items.size() < 90);

  const rfbsim::sim::Prop desk{0.0, 0.0, 1.4, 0.7, 1.2, 0x8a6d4b, 0.0, rfbsim::sim::PropKind::Desk};
  items.clear();
  rfbsim::sim::append_prop(items, desk);
  // The first item is the tabletop: 1.4 x 0.7 m with its top at 0.744 m (0.62 of the 1.2 m prop).
  CHECK(corners(items[0])[7].z() == Approx(0.744f));
  CHECK(items[0].model.linear().col(0).norm() == Approx(1.4f));
}

TEST_CASE("scene: the world's things are all in the scene at their places", "[scene]") {
  const auto world = small_world();
  const auto scene = rfbsim::sim::build_scene(world);
  // Every part's items are in the scene.
  std::vector<DrawItem> parts;
  for (const auto& prop : world.props) rfbsim::sim::append_prop(parts, prop);
  for (const auto& landmark : world.landmarks) rfbsim::sim::append_landmark(parts, landmark);
  rfbsim::sim::append_robot(parts, *world.robot);
  for (const auto& person : world.people) rfbsim::sim::append_person(parts, person);
  for (const DrawItem& part : parts) {
    CHECK(std::any_of(scene.items.begin(), scene.items.end(),
                      [&](const DrawItem& item) { return item.model.matrix() == part.model.matrix(); }));
  }
  // The landmark's pole: a cylinder at its x, y, taller than the walls.
  CHECK(std::any_of(scene.items.begin(), scene.items.end(), [](const DrawItem& item) {
    return item.shape == Shape::Cylinder && horizontal_distance(item, 1.0, 8.0) < 1e-4 && corners(item)[7].z() > 2.5f;
  }));
  // The robot: its dome's top at its 0.5 m height, and its eyes ahead of its centre (it faces +x).
  std::vector<DrawItem> robot;
  rfbsim::sim::append_robot(robot, *world.robot);
  double top = 0.0;
  int eyes = 0;
  for (const DrawItem& item : robot) {
    if (item.opacity < 1.0f) continue;
    top = std::max(top, static_cast<double>(corners(item)[7].z()));
    if (item.shape == Shape::Sphere && item.color.maxCoeff() < 0.1f) {
      ++eyes;
      CHECK(item.model.translation().x() > 3.1f);
    }
  }
  CHECK(top == Approx(0.5).margin(0.02));
  CHECK(eyes == 2);
}

TEST_CASE("scene: building is deterministic and a warehouse stays within the item budget", "[scene]") {
  auto world = small_world();
  CHECK(rfbsim::sim::same_scene(rfbsim::sim::build_scene(world), rfbsim::sim::build_scene(world)));
  world.people[1].gait_phase += 0.5;
  world.people[1].velocity = {1.0, 0.0};
  CHECK_FALSE(rfbsim::sim::same_scene(rfbsim::sim::build_scene(small_world()), rfbsim::sim::build_scene(world)));

  // 30 racks 8 m long and 15 walkers, as in a large warehouse.
  world.props.clear();
  for (int i = 0; i < 30; ++i) {
    world.props.push_back(
        {1.0 + 2.5 * (i % 10), 5.0 + 10.0 * (i / 10), 1.0, 8.0, 2.4, 0xb08850, 0.0, rfbsim::sim::PropKind::Shelf});
  }
  world.people.resize(15);
  for (int i = 0; i < 15; ++i) world.people[static_cast<std::size_t>(i)].id = i + 1;
  const auto scene = rfbsim::sim::build_scene(world);
  INFO("items: " << scene.items.size());
  CHECK(scene.items.size() < 2500);
}

TEST_CASE("scene: the robot's head, face and eyes turn with head_yaw", "[scene]") {
  using rfbsim::sim::kRobotBodyItems;
  using rfbsim::sim::kRobotHeadItems;
  const RobotHeadViews views = robot_head_views();
  const std::vector<DrawItem>& ahead = views.ahead;
  const std::vector<DrawItem>& turned = views.turned;
  for (std::size_t i = kRobotBodyItems; i < kRobotBodyItems + kRobotHeadItems; ++i) {
    INFO("item " << i);
    CHECK_FALSE(ahead[i].model.matrix().isApprox(turned[i].model.matrix()));
  }
  // The eyes (black) sit either side of the head's forward axis: their midpoint points along the body's
  // yaw plus the head's, 0.1175 m out (1.02 x the head's 0.1152 m radius), at 0.43 m.
  const std::size_t eye = kRobotBodyItems + 2;
  const auto eyes_direction = [&](const std::vector<DrawItem>& items) {
    CHECK(items[eye].color.maxCoeff() < 0.1f);
    CHECK(items[eye + 2].color.maxCoeff() < 0.1f);
    const Eigen::Vector3f mid = 0.5f * (items[eye].model.translation() + items[eye + 2].model.translation());
    CHECK(std::hypot(mid.x() - 3.0f, mid.y() - 5.0f) == Approx(1.02 * 0.72 * 0.16).epsilon(1e-4));
    CHECK(mid.z() == Approx(0.5 - 0.08 + 0.01).epsilon(1e-4));
    return std::atan2(static_cast<double>(mid.y()) - 5.0, static_cast<double>(mid.x()) - 3.0);
  };
  CHECK(eyes_direction(ahead) == Approx(0.4).margin(1e-5));
  CHECK(eyes_direction(turned) == Approx(1.3).margin(1e-5));
}

TEST_CASE("scene: the robot's body and shadow do not turn with head_yaw", "[scene]") {
  using rfbsim::sim::kRobotBodyItems;
  using rfbsim::sim::kRobotHeadItems;
  const RobotHeadViews views = robot_head_views();
  const std::vector<DrawItem>& ahead = views.ahead;
  const std::vector<DrawItem>& turned = views.turned;
  for (std::size_t i = 0; i < ahead.size(); ++i) {
    if (i >= kRobotBodyItems && i < kRobotBodyItems + kRobotHeadItems) continue;  // the head
    INFO("item " << i);
    CHECK(ahead[i].model.matrix().isApprox(turned[i].model.matrix()));
  }
  // The sensor window and the heart light stay on the body's front whichever way the head looks.
  for (const std::size_t i : {kRobotBodyItems - 2, kRobotBodyItems - 1}) {
    const Eigen::Vector3f front = turned[i].model.translation();
    CHECK(std::atan2(static_cast<double>(front.y()) - 5.0, static_cast<double>(front.x()) - 3.0) ==
          Approx(0.4).margin(1e-5));
  }
}

TEST_CASE("scene: the robot with its head turned reaches its height and fills its footprint, no further",
          "[scene]") {
  const std::vector<DrawItem> turned = robot_head_views().turned;
  // The top of the dome is the robot's height, turned or not, and the body fills its footprint without
  // reaching past it: every part is a sphere or cylinder turned about z, so its reach along a horizontal
  // direction u is its centre's plus half the length of its unit shape's axes projected on u.
  double top = 0.0;
  double widest = 0.0;
  for (const DrawItem& item : turned) {
    if (item.opacity < 1.0f) continue;  // the shadow is wider on purpose
    REQUIRE(item.shape != Shape::Box);
    top = std::max(top, static_cast<double>(corners(item)[7].z()));
    for (int k = 0; k < 72; ++k) {
      const float angle = 0.087266f * static_cast<float>(k);  // every 5 degrees
      const Eigen::Vector3f u(std::cos(angle), std::sin(angle), 0.0f);
      const float reach = (item.model.translation() - Eigen::Vector3f(3.0f, 5.0f, 0.0f)).dot(u) +
                          0.5f * (item.model.linear().transpose() * u).norm();
      widest = std::max(widest, static_cast<double>(reach));
    }
  }
  CHECK(top == Approx(0.5).margin(1e-4));
  CHECK(widest == Approx(0.16).margin(1e-4));
}

TEST_CASE("scene: the robot's heart light tells the navigator's state", "[scene]") {
  const std::size_t light = rfbsim::sim::kRobotBodyItems - 1;
  rfbsim::sim::Robot robot;
  std::vector<DrawItem> moving, failed;
  robot.state = rfbsim::sim::RobotState::Moving;
  rfbsim::sim::append_robot(moving, robot);
  robot.state = rfbsim::sim::RobotState::Failed;
  rfbsim::sim::append_robot(failed, robot);
  REQUIRE(moving.size() == failed.size());
  for (std::size_t i = 0; i < moving.size(); ++i) {
    INFO("item " << i);
    CHECK((moving[i].color == failed[i].color) == (i != light));
  }
  CHECK(failed[light].color.x() > 0.9f);  // red
  CHECK(failed[light].color.y() < 0.3f);
}

TEST_CASE("scene: a robot with a broken pose or no radius draws nothing", "[scene]") {
  rfbsim::sim::Robot robot;
  std::vector<DrawItem> none;
  robot.pose.x = std::nan("");
  rfbsim::sim::append_robot(none, robot);
  CHECK(none.empty());
  robot.pose.x = 1.0;
  robot.radius = 0.0;
  rfbsim::sim::append_robot(none, robot);
  CHECK(none.empty());
}

TEST_CASE("scene: a robot with a broken head angle is drawn whole, its head looking ahead", "[scene]") {
  rfbsim::sim::Robot robot;
  robot.pose = {1.0, 0.0, 0.0};
  std::vector<DrawItem> ahead, broken;
  rfbsim::sim::append_robot(ahead, robot);
  robot.head_yaw = std::nan("");
  rfbsim::sim::append_robot(broken, robot);
  REQUIRE(broken.size() == ahead.size());
  for (std::size_t i = 0; i < broken.size(); ++i) {
    INFO("item " << i);
    CHECK(broken[i].model.matrix().allFinite());
    CHECK(broken[i].model.matrix().isApprox(ahead[i].model.matrix()));
  }
}

TEST_CASE("scenes compare equal until the world moves") {
  auto world = rfbsim::sim::make_demo_world();
  const auto a = rfbsim::sim::build_scene(world);
  CHECK(rfbsim::sim::same_scene(a, rfbsim::sim::build_scene(world)));
  world.avatar.pose.x += 0.001;
  CHECK_FALSE(rfbsim::sim::same_scene(a, rfbsim::sim::build_scene(world)));
  world = rfbsim::sim::make_demo_world();
  world.camera.height += 0.1;
  CHECK_FALSE(rfbsim::sim::same_scene(a, rfbsim::sim::build_scene(world)));
}
