// SPDX-License-Identifier: GPL-2.0-or-later
// The first-person view: the camera at the avatar's eye looking where it faces, the avatar's body left out,
// the rig's height ignored, the top view unchanged, and a picture that differs from the third-person one.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "app/session_setup.hpp"
#include "render/gl_renderer.hpp"
#include "render/scene_builder.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "world/demo_world.hpp"

namespace {

using rfbsim::sim::CameraMode;
using rfbsim::sim::SceneStyle;

SceneStyle style_of(CameraMode mode) {
  SceneStyle style;
  style.camera = mode;
  return style;
}

// Items standing near (x, y) above the floor's slab: the avatar's body parts when it stands there alone.
int items_near(const rfbsim::sim::Scene& scene, double x, double y, double radius) {
  int count = 0;
  for (const rfbsim::sim::DrawItem& item : scene.items) {
    const Eigen::Vector3f t = item.model.translation();
    if (std::hypot(static_cast<double>(t.x()) - x, static_cast<double>(t.y()) - y) < radius && t.z() > -0.01f) ++count;
  }
  return count;
}

}  // namespace

TEST_CASE("first person: the eye is 1.62 m above the avatar's feet, looking along its yaw 10 degrees down") {
  rfbsim::sim::Avatar avatar;
  avatar.pose = {3.0, -2.0, std::numbers::pi / 2.0};  // facing +y
  const rfbsim::sim::ViewCamera camera = rfbsim::sim::first_person_camera(avatar, style_of(CameraMode::kFirstPerson));
  CHECK(camera.eye.x() == Approx(3.0));
  CHECK(camera.eye.y() == Approx(-2.0));
  CHECK(camera.eye.z() == Approx(1.62));
  const Eigen::Vector3f gaze = (camera.target - camera.eye).normalized();
  const float down = static_cast<float>(std::sin(10.0 * std::numbers::pi / 180.0));
  CHECK(gaze.x() == Approx(0.0).margin(1e-6));
  CHECK(gaze.y() == Approx(std::sqrt(1.0 - static_cast<double>(down * down))));
  CHECK(gaze.z() == Approx(-static_cast<double>(down)));
}

TEST_CASE("first person: build_scene uses that camera whatever the rig's height") {
  rfbsim::sim::World world = rfbsim::sim::make_demo_world();
  world.camera.height = 5.5;  // Up held for a while: moves the third-person camera only
  const auto scene = rfbsim::sim::build_scene(world, style_of(CameraMode::kFirstPerson));
  const auto expected = rfbsim::sim::first_person_camera(world.avatar, style_of(CameraMode::kFirstPerson));
  CHECK(scene.camera.eye == expected.eye);
  CHECK(scene.camera.target == expected.target);
  const auto third = rfbsim::sim::build_scene(world, style_of(CameraMode::kThirdPerson));
  CHECK(third.camera.eye.z() == Approx(5.5));
}

TEST_CASE("first person: the avatar and its shadow are left out, everything else is the same") {
  const rfbsim::sim::World world = rfbsim::sim::make_demo_world();
  const auto third = rfbsim::sim::build_scene(world, style_of(CameraMode::kThirdPerson));
  const auto first = rfbsim::sim::build_scene(world, style_of(CameraMode::kFirstPerson));
  const double x = world.avatar.pose.x, y = world.avatar.pose.y;
  // The third-person scene has a whole humanoid and a shadow within half a metre of the avatar's feet.
  const int avatar_items = items_near(third, x, y, 0.5);
  REQUIRE(avatar_items > 10);
  CHECK(items_near(first, x, y, 0.5) == 0);
  CHECK(first.items.size() + static_cast<std::size_t>(avatar_items) == third.items.size());
}

TEST_CASE("first person: the top view still shows the avatar from above") {
  const rfbsim::sim::World world = rfbsim::sim::make_demo_world();
  SceneStyle top = style_of(CameraMode::kFirstPerson);
  top.top_view = true;
  SceneStyle top_third = style_of(CameraMode::kThirdPerson);
  top_third.top_view = true;
  CHECK(rfbsim::sim::same_scene(rfbsim::sim::build_scene(world, top), rfbsim::sim::build_scene(world, top_third)));
}

TEST_CASE("first person: the lab at the same seed and tick looks different from the third-person view") {
  rfbsim::sim::SessionSetup setup;
  setup.scenario = "lab";
  setup.seed = 7;
  rfbsim::sim::PreparedSession prepared = rfbsim::sim::prepare_session(setup);
  for (int tick = 0; tick < 30; ++tick) prepared.simulation->step();
  const rfbsim::sim::World& world = prepared.simulation->world();

  rfbsim::OffscreenGL gl({320, 180, 4, "auto"});
  rfbsim::sim::GlRenderer renderer;
  const auto picture = [&](CameraMode mode) {
    gl.begin_frame();
    renderer.draw(rfbsim::sim::build_scene(world, style_of(mode)), 320, 180);
    const auto frame = gl.read_frame();
    std::vector<std::uint8_t> pixels;
    for (int y = 0; y < frame.height; ++y) pixels.insert(pixels.end(), frame.row(y), frame.row(y) + frame.width * 4);
    return pixels;
  };
  const auto third = picture(CameraMode::kThirdPerson);
  const auto first = picture(CameraMode::kFirstPerson);
  REQUIRE(third.size() == first.size());
  // Not a pixel or two: a different viewpoint changes a large part of the frame.
  std::size_t differing = 0;
  for (std::size_t i = 0; i < third.size(); i += 4) {
    if (third[i] != first[i] || third[i + 1] != first[i + 1] || third[i + 2] != first[i + 2]) ++differing;
  }
  CHECK(differing > third.size() / 4 / 10);
  // Drawing the same view again gives the same picture: the difference is the camera's, not noise.
  CHECK(picture(CameraMode::kFirstPerson) == first);
}
