// SPDX-License-Identifier: GPL-2.0-or-later
// Task types' names and default wording.
#include "task/task_spec.hpp"

#include <array>
#include <utility>

namespace rfbsim::sim {

namespace {

constexpr std::array<std::pair<TaskType, const char*>, 6> kNames = {{
    {TaskType::Walk, "walk"},
    {TaskType::Turn, "turn"},
    {TaskType::Camera, "camera"},
    {TaskType::FindRobot, "find_robot"},
    {TaskType::FollowRobot, "follow_robot"},
    {TaskType::Reach, "reach"},
}};

}  // namespace

const char* task_type_name(TaskType type) {
  for (const auto& [t, name] : kNames) {
    if (t == type) return name;
  }
  return "unknown";
}

std::optional<TaskType> task_type_from_name(const std::string& name) {
  for (const auto& [t, n] : kNames) {
    if (name == n) return t;
  }
  return std::nullopt;
}

std::string task_step_text(const TaskStep& step) {
  if (!step.text.empty()) return step.text;
  switch (step.type) {
    case TaskType::Walk: return "Hold W to walk forward (S walks back)";
    case TaskType::Turn: return "Turn around with A and D";
    case TaskType::Camera: return "Raise or lower the camera with the Up and Down arrows";
    case TaskType::FindRobot: return "Find the robot";
    case TaskType::FollowRobot: return "Follow the robot: stay close to it";
    case TaskType::Reach: return "Walk to the yellow marker on the floor";
  }
  return "";
}

}  // namespace rfbsim::sim
