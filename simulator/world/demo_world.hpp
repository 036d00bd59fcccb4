// SPDX-License-Identifier: GPL-2.0-or-later
// make_demo_world: the built-in test room with a few crates, used until scenario files arrive.
#pragma once

#include "world/world.hpp"

namespace rfbsim::sim {

/// The test room (see builtin_test_room) with crates, the avatar at its start facing +y.
World make_demo_world();

}  // namespace rfbsim::sim
