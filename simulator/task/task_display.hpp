// SPDX-License-Identifier: GPL-2.0-or-later
// The task's words on screen: what the HUD says while the task runs and after its outcome. Pure text;
// app/ turns it into HUD panels.
#pragma once

#include <string>
#include <vector>

#include "task/task_monitor.hpp"

namespace rfbsim::sim {

struct TaskText {
  std::vector<std::string> corner;  ///< while it runs: step, instruction, progress, time left; empty after
  std::vector<std::string> centre;  ///< after the outcome: what happened, and the completion code if any
  bool operator==(const TaskText&) const = default;
};

/// The words for `status`. `code` is the completion code for the outcome reached (empty: none to show).
/// Time left shows as m:ss, rounded up, so that "0:00" means the time is up.
TaskText task_text(const TaskSpec& spec, const TaskStatus& status, const std::string& code);

/// The words for a replay's watcher (sim_rfb --replay): the walker's HUD less what was addressed to the walker.
/// Kept: the step count, the progress and the time left while the task runs, and what the outcome was.
/// Dropped: the step's instruction (a watcher has nothing to do), "Thank you!" and the completion code (the
/// walker's, not the watcher's).
TaskText watched_task_text(const TaskSpec& spec, const TaskStatus& status);

}  // namespace rfbsim::sim
