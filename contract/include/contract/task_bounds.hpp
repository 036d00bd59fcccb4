// SPDX-License-Identifier: GPL-2.0-or-later
// The bounds of a scenario task's clock, in seconds, as sim_rfb enforces them (the scenario's task.time_limit and
// task.end_grace, and the --time-limit and --end-grace flags) and as sim_manager assumes them (a session's
// maximum duration must fit the task, and it reads --time-limit from its session_args). One definition, so that
// the manager never accepts a value the simulator refuses.
#pragma once

namespace rfbsim::contract {

/// The task's time limit, s: at least 1 s, at most a day (a study session is minutes; a day is a typo's bound).
constexpr int kMinTimeLimitS = 1;
constexpr int kMaxTimeLimitS = 86400;

/// How long the outcome and its code stay on screen before the session ends, s: 0 (at once) to an hour.
constexpr int kMinEndGraceS = 0;
constexpr int kMaxEndGraceS = 3600;

}  // namespace rfbsim::contract
