// SPDX-License-Identifier: GPL-2.0-or-later
// TaskSpec: what the participant is asked to do in a scenario (the model; never changes in a session):
// steps in order, a time limit and how long the outcome stays on screen. Loaded from the scenario's `task`.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::sim {

/// The kinds of step. The study's three (SEAN-EP) come last; the first three teach the keys (tutorial).
enum class TaskType {
  Walk,         ///< walk `distance` m in total (W/S)
  Turn,         ///< turn `angle` rad in total (A/D)
  Camera,       ///< raise or lower the camera by `distance` m in total (Up/Down)
  FindRobot,    ///< have the robot in view: within `distance` m, within `view_angle` of the avatar's heading, unobstructed
  FollowRobot,  ///< stay within `distance` m of the robot for `duration` s in total
  Reach,        ///< stand within `distance` m of the target (a landmark; the avatar's goal by default)
};

/// The scenario's name of a type ("find_robot"), as in files, events and reports.
const char* task_type_name(TaskType type);
/// The type named `name`, or nothing.
std::optional<TaskType> task_type_from_name(const std::string& name);

/// One step, with the defaults the SEAN-EP study used where it had one.
struct TaskStep {
  TaskType type = TaskType::Reach;
  std::string text;           ///< what the HUD says; empty = the type's default wording
  double distance = 0.3;      ///< m: Walk/Camera amount, FindRobot/FollowRobot range, Reach tolerance (SEAN-EP: 0.3)
  double angle = 6.2832;      ///< rad, Turn: total turning asked for
  double duration = 30.0;     ///< s, FollowRobot: time within range, in total
  double view_angle = 0.785;  ///< rad, FindRobot: half-width of the view the robot must be in (about the camera's)
  std::string landmark;       ///< Reach: a landmark's name; empty = the avatar's goal
  std::optional<Eigen::Vector2d> target;  ///< Reach: where, resolved from the scenario (m)
};

/// The participant's task in one scenario. No steps = no task (no HUD, no outcome).
struct TaskSpec {
  std::vector<TaskStep> steps;
  double time_limit = 240.0;  ///< s from the first viewer to a timeout (SEAN-EP's in-game timer: 4 min)
  double end_grace = 15.0;    ///< s the outcome and code stay on screen before the session ends
};

/// The HUD's wording for a step: its own text, or the type's default.
std::string task_step_text(const TaskStep& step);

}  // namespace rfbsim::sim
