// SPDX-License-Identifier: GPL-2.0-or-later
// The built-in demo world.
#include "world/demo_world.hpp"

#include <numbers>

namespace rfbsim::sim {

World make_demo_world() {
  World world;
  world.map = builtin_test_room();
  // Crates of a few sizes and colours, placed off the avatar's first straight walk.
  world.props = {
      {-3.5, -2.5, 0.8, 0.8, 0.8, 0xb08850},
      {-4.2, -1.2, 0.6, 0.6, 1.2, 0x9a7444},
      {-2.0, 2.5, 1.2, 0.6, 0.9, 0x6f8f5a},
      {4.8, -3.0, 0.7, 0.7, 0.7, 0xc0623a},
      {5.0, 3.2, 0.8, 1.4, 1.0, 0x5a78a0},
      {-4.5, 3.5, 0.8, 0.8, 1.6, 0xb08850},
  };
  world.obstacles = with_props_blocked(world.map, world.props);
  world.avatar.pose = {3.5, -1.0, std::numbers::pi / 2.0};
  return world;
}

}  // namespace rfbsim::sim
