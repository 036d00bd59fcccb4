// SPDX-License-Identifier: GPL-2.0-or-later
// The task's words on screen.
#include "task/task_display.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace rfbsim::sim {

namespace {

std::string clock_text(double seconds) {
  const long whole = static_cast<long>(std::ceil(seconds - 1e-9));
  char text[64];
  std::snprintf(text, sizeof text, "Time left %ld:%02ld", whole / 60, whole % 60);
  return text;
}

// "Walked 1.2 / 3.0 m": how far along a step that adds up is; empty for yes/no steps.
std::string progress_text(const TaskStep& step, const TaskStatus& status) {
  char text[64];
  switch (step.type) {
    case TaskType::Walk:
      std::snprintf(text, sizeof text, "Walked %.1f / %.1f m", std::min(status.amount, status.goal), status.goal);
      return text;
    case TaskType::Camera:
      std::snprintf(text, sizeof text, "Camera moved %.1f / %.1f m", std::min(status.amount, status.goal),
                    status.goal);
      return text;
    case TaskType::Turn:
      std::snprintf(text, sizeof text, "Turned %.0f / %.0f degrees",
                    std::min(status.amount, status.goal) * 180.0 / std::numbers::pi, status.goal * 180.0 / std::numbers::pi);
      return text;
    case TaskType::FollowRobot:
      std::snprintf(text, sizeof text, "Following: %.0f / %.0f s", std::floor(std::min(status.amount, status.goal)),
                    status.goal);
      return text;
    case TaskType::FindRobot:
    case TaskType::Reach: break;
  }
  return "";
}

}  // namespace

TaskText task_text(const TaskSpec& spec, const TaskStatus& status, const std::string& code) {
  TaskText text;
  if (spec.steps.empty()) return text;
  if (status.outcome != TaskOutcome::None) {
    text.centre.push_back(status.outcome == TaskOutcome::Completed ? "Task complete. Thank you!"
                                                                   : "Time is up. Thank you!");
    if (!code.empty()) {
      text.centre.push_back("Your completion code:");
      text.centre.push_back(code);
    }
    return text;
  }
  const int count = static_cast<int>(spec.steps.size());
  const int index = std::clamp(status.step, 0, count - 1);
  const TaskStep& step = spec.steps[static_cast<std::size_t>(index)];
  text.corner.push_back("Task " + std::to_string(index + 1) + " of " + std::to_string(count));
  text.corner.push_back(task_step_text(step));
  if (const std::string progress = progress_text(step, status); !progress.empty()) text.corner.push_back(progress);
  text.corner.push_back(clock_text(status.time_left));
  return text;
}

TaskText watched_task_text(const TaskSpec& spec, const TaskStatus& status) {
  TaskText text = task_text(spec, status, "");
  if (!text.corner.empty()) text.corner.erase(text.corner.begin() + 1);  // the instruction, always the second line
  if (!text.centre.empty()) {
    text.centre = {status.outcome == TaskOutcome::Completed ? "The task was completed." : "The time ran out."};
  }
  return text;
}

}  // namespace rfbsim::sim
