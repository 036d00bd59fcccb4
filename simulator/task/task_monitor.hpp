// SPDX-License-Identifier: GPL-2.0-or-later
// TaskMonitor: watches the world tick by tick and tells how far the participant is with the task: which
// step, its progress, the time left, and the outcome (completed, or timeout). It reads the world and never
// changes it; its events are recorded and its status drives the HUD.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "task/task_spec.hpp"
#include "world/world.hpp"

namespace rfbsim::sim {

/// How a session's task ended.
enum class TaskOutcome { None, Completed, Timeout };

/// "completed", "timeout" (and "none"), as in events, session.json and the manager's index.
const char* task_outcome_name(TaskOutcome outcome);

/// Something that happened to the task at a tick.
struct TaskEvent {
  enum class Kind { TimerStarted, StepStarted, StepDone, Outcome };
  Kind kind = Kind::TimerStarted;
  std::uint64_t tick = 0;
  int index = -1;  ///< the step, for StepStarted and StepDone
  TaskOutcome outcome = TaskOutcome::None;  ///< for Outcome
};

/// Where the participant stands, for the HUD.
struct TaskStatus {
  bool timer_running = false;  ///< false before the first viewer
  int step = -1;               ///< index of the current step; -1 before the timer; steps.size() when all done
  double amount = 0.0;         ///< of the current step: m walked, rad turned, s followed... (0 for yes/no steps)
  double goal = 0.0;           ///< what `amount` must reach (0 for yes/no steps: find, reach)
  double time_left = 0.0;      ///< s until the timeout (the whole limit before the timer starts)
  TaskOutcome outcome = TaskOutcome::None;
};

class TaskMonitor {
 public:
  /// `dt`: seconds per tick. A spec without steps makes an inactive monitor: no events, no outcome.
  TaskMonitor(TaskSpec spec, double dt);

  [[nodiscard]] bool active() const { return !spec_.steps.empty(); }
  /// Starts the clock and the first step at the world's current tick (sim_rfb: the first viewer arrived).
  /// Later calls do nothing.
  void start_timer(const World& world);
  /// Takes one tick of the world after it was stepped: progress, step changes, the outcome.
  void observe(const World& world);

  /// The events since the last clear_events(), in order.
  [[nodiscard]] const std::vector<TaskEvent>& events() const { return events_; }
  void clear_events() { events_.clear(); }

  [[nodiscard]] TaskStatus status() const;
  [[nodiscard]] TaskOutcome outcome() const { return outcome_; }
  /// The tick of the outcome; none while there is none.
  [[nodiscard]] std::optional<std::uint64_t> outcome_tick() const { return outcome_tick_; }
  [[nodiscard]] const TaskSpec& spec() const { return spec_; }

 private:
  void begin_step(std::uint64_t tick);
  // Adds this tick's progress on the current step; true when the step is done.
  bool advance(const World& world);
  void finish(TaskOutcome outcome, std::uint64_t tick);

  TaskSpec spec_;
  double dt_;
  std::optional<std::uint64_t> start_tick_;
  std::uint64_t last_tick_ = 0;
  int step_ = -1;
  double amount_ = 0.0;
  // The avatar and camera as at the last tick observed, for the steps that add up change.
  double last_walked_ = 0.0, last_yaw_ = 0.0, last_camera_ = 0.0;
  TaskOutcome outcome_ = TaskOutcome::None;
  std::optional<std::uint64_t> outcome_tick_;
  std::vector<TaskEvent> events_;
};

/// Whether the robot is in the avatar's view: within `range` m, within `half_angle` rad of the avatar's
/// heading, and no wall or prop between them (World::obstacles). False without a robot.
bool robot_in_view(const World& world, double range, double half_angle);

}  // namespace rfbsim::sim
