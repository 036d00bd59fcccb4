// SPDX-License-Identifier: GPL-2.0-or-later
// Missions: what the robot is sent to do (from the scenario), and the order in which its goals come.
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "world/world.hpp"

namespace rfbsim::sim {

/// What the robot does (carried out by the navigator, goal after goal).
struct MissionSpec {
  enum class Kind { None, GoTo, Patrol, Wander };
  Kind kind = Kind::None;
  std::vector<Pose2> waypoints;  ///< GoTo: one goal; Patrol: the loop; Wander: the places to pick from
  std::vector<std::string> waypoint_names;  ///< the spawn names they came from ("" for literal poses)
};

/// Hands out a mission's goals in order: GoTo's one goal; Patrol's waypoints round and round; Wander's
/// places picked at random (never the same twice in a row), from its own seeded stream.
class MissionRunner {
 public:
  MissionRunner(MissionSpec spec, std::uint64_t seed);

  /// The next goal, or none when the mission has nothing more (GoTo after its goal, None at once).
  std::optional<Pose2> next_goal();
  /// The name of the goal last handed out ("" for a literal pose).
  [[nodiscard]] const std::string& goal_name() const { return name_; }
  [[nodiscard]] const MissionSpec& spec() const { return spec_; }

 private:
  MissionSpec spec_;
  std::mt19937_64 rng_;
  std::size_t handed_out_ = 0;
  std::optional<std::size_t> last_;
  std::string name_;
};

}  // namespace rfbsim::sim
