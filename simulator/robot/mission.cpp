// SPDX-License-Identifier: GPL-2.0-or-later
// MissionRunner: the order of a mission's goals.
#include "robot/mission.hpp"

#include <utility>

namespace rfbsim::sim {

MissionRunner::MissionRunner(MissionSpec spec, std::uint64_t seed) : spec_(std::move(spec)), rng_(seed) {}

std::optional<Pose2> MissionRunner::next_goal() {
  const std::size_t count = spec_.waypoints.size();
  if (count == 0) return std::nullopt;
  std::size_t pick = 0;
  switch (spec_.kind) {
    case MissionSpec::Kind::None:
      return std::nullopt;
    case MissionSpec::Kind::GoTo:
      if (handed_out_ > 0) return std::nullopt;
      pick = 0;
      break;
    case MissionSpec::Kind::Patrol:
      pick = handed_out_ % count;
      break;
    case MissionSpec::Kind::Wander:
      if (count == 1) {
        pick = 0;
      } else {
        // Uniform over the places other than the last one.
        std::uniform_int_distribution<std::size_t> other(0, last_ ? count - 2 : count - 1);
        pick = other(rng_);
        if (last_ && pick >= *last_) ++pick;
      }
      break;
  }
  ++handed_out_;
  last_ = pick;
  name_ = pick < spec_.waypoint_names.size() ? spec_.waypoint_names[pick] : std::string();
  return spec_.waypoints[pick];
}

}  // namespace rfbsim::sim
