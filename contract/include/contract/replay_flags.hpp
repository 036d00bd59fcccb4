// SPDX-License-Identifier: GPL-2.0-or-later
// The sim_rfb flags that make a world of their own (a scenario, a seed, poses, a crowd, who drives the robot,
// a time limit): `sim_rfb --replay` shows a recorded world as it was and refuses them, and sim_manager leaves
// them out of a video-condition session's extra arguments (session_args), so that a study's settings for its
// walkers do not make its watchers' sessions fail. Each takes a value.
#pragma once

#include <array>
#include <string_view>

namespace rfbsim::contract {

inline constexpr std::array<std::string_view, 9> kWorldFlags = {
    "--scenario",  "--seed",       "--crowd",       "--robot-control", "--time-limit",
    "--avatar-start", "--avatar-goal", "--robot-start", "--robot-goal"};

}  // namespace rfbsim::contract
