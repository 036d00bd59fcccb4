// SPDX-License-Identifier: GPL-2.0-or-later
// The `task` section of a scenario.
#include "scenario/task_yaml.hpp"

#include <algorithm>

#include "contract/task_bounds.hpp"
#include "scenario/scenario.hpp"

namespace rfbsim::sim {

namespace {

TaskStep parse_step(const YamlField& item, const std::vector<Landmark>& landmarks) {
  item.allow_only({"type", "text", "distance", "angle", "duration", "view_angle", "landmark", "tolerance"});
  const YamlField type_field = item.required("type");
  const auto type = task_type_from_name(type_field.text());
  if (!type) type_field.fail("one of walk, turn, camera, find_robot, follow_robot, reach");
  TaskStep step;
  step.type = *type;
  // Defaults per type: SEAN-EP's where it had them (reach within 0.3 m), else what a first session needs.
  switch (step.type) {
    case TaskType::Walk: step.distance = 3.0; break;
    case TaskType::Camera: step.distance = 0.5; break;
    case TaskType::FindRobot: step.distance = 5.0; break;
    case TaskType::FollowRobot: step.distance = 2.0; break;
    case TaskType::Turn:
    case TaskType::Reach: break;
  }
  if (auto text = item.optional("text")) step.text = text->text();
  if (auto distance = item.optional("distance")) step.distance = distance->number(0.05, 100.0);
  if (auto tolerance = item.optional("tolerance")) {
    if (step.type != TaskType::Reach) tolerance->fail_with("only a reach step has a tolerance");
    step.distance = tolerance->number(0.05, 10.0);
  }
  if (auto angle = item.optional("angle")) step.angle = angle->number(0.1, 100.0);
  if (auto duration = item.optional("duration")) step.duration = duration->number(0.1, 3600.0);
  if (auto view = item.optional("view_angle")) step.view_angle = view->number(0.05, 3.1416);
  if (auto landmark = item.optional("landmark")) {
    if (step.type != TaskType::Reach) landmark->fail_with("only a reach step has a landmark");
    step.landmark = landmark->text();
    const bool known = std::any_of(landmarks.begin(), landmarks.end(),
                                   [&](const Landmark& l) { return l.name == step.landmark; });
    if (!known) landmark->fail_with("no landmark named '" + step.landmark + "' in this scenario");
  }
  return step;
}

}  // namespace

TaskSpec parse_task(const YamlField& task, const std::vector<Landmark>& landmarks) {
  task.allow_only({"time_limit", "end_grace", "steps"});
  TaskSpec spec;
  // The bounds sim_manager assumes too (a session's maximum duration must fit the task).
  using namespace contract;
  if (auto limit = task.optional("time_limit")) spec.time_limit = limit->number(kMinTimeLimitS, kMaxTimeLimitS);
  if (auto grace = task.optional("end_grace")) spec.end_grace = grace->number(kMinEndGraceS, kMaxEndGraceS);
  for (const YamlField& item : task.required("steps").sequence(1, 50)) spec.steps.push_back(parse_step(item, landmarks));
  return spec;
}

void resolve_task_targets(TaskSpec& spec, const std::vector<Landmark>& landmarks, const Landmark* avatar_goal) {
  for (TaskStep& step : spec.steps) {
    if (step.type != TaskType::Reach) continue;
    const Landmark* target = avatar_goal;
    for (const Landmark& l : landmarks) {
      if (!step.landmark.empty() && l.name == step.landmark) target = &l;
    }
    if (target == nullptr) {
      throw ScenarioError("task: a reach step without a landmark needs the scenario's avatar.goal");
    }
    step.target = Eigen::Vector2d(target->x, target->y);
  }
}

}  // namespace rfbsim::sim
