// SPDX-License-Identifier: GPL-2.0-or-later
// StudySession: one participant's session around a Simulation: inputs and viewers in (recorded at the
// tick they are applied), then per tick the simulation, the task monitor and the session data. sim_rfb
// drives it live; sim_replay drives it from a log, so that both take the same path through the same code.
#pragma once

#include <cstdint>
#include <string>

#include "app/simulation.hpp"
#include "record/session_writer.hpp"
#include "task/task_display.hpp"
#include "task/task_monitor.hpp"

namespace rfbsim::sim {

/// Who a viewer is: the participant, whose first sight of the world starts the task's clock, or a researcher
/// watching through sim_manager's view-only relay, who must never start it.
enum class ViewerRole { kParticipant, kWatcher };

/// "participant" or "watcher", as session data records it.
const char* viewer_role_name(ViewerRole role);

/// The completion codes a link carried (SEAN-EP's t1 and t2); empty = none to show.
struct StudyCodes {
  std::string success;
  std::string timeout;
};

class StudySession {
 public:
  /// `writer` may be null (nothing recorded); both `simulation` and `writer` must outlive this.
  StudySession(Simulation& simulation, TaskSpec task, StudyCodes codes, SessionWriter* writer);

  /// A key event; it takes effect from the next step. `client` 0: librfbsim releasing a leaver's keys.
  void key(std::uint32_t keysym, bool down, int client);
  /// An external controller's velocity command (ROS /cmd_vel, docs/ros.md), recorded as a `robot_command`
  /// event with its `source` and applied from the next step, as a key is. False (and nothing recorded) when the
  /// robot is not under external control: the command is ignored.
  bool robot_command(double v, double w, const std::string& source);
  /// Pointer moves and buttons: recorded, not used.
  void pointer(int x, int y, int buttons, int client);
  /// A viewer arrived: recorded with its hashed address and role; the first participant starts the task's
  /// clock (a watcher is recorded with "role":"watcher" and starts nothing).
  void client_connected(int client, const std::string& address_hash, bool websocket,
                        ViewerRole role = ViewerRole::kParticipant);
  /// A viewer left (recorded with the same hashed address as its connect).
  void client_disconnected(int client, const std::string& address_hash, bool websocket);

  /// One tick: simulation, task, then the tick's trajectory sample and events.
  void step();

  /// The outcome was reached and its grace period has passed: the session should end.
  [[nodiscard]] bool over() const;
  [[nodiscard]] TaskOutcome outcome() const { return monitor_.outcome(); }
  /// The code for the outcome reached (empty without outcome or without codes).
  [[nodiscard]] std::string outcome_code() const;
  /// What the HUD shows now.
  [[nodiscard]] TaskText text() const { return task_text(monitor_.spec(), monitor_.status(), outcome_code()); }
  [[nodiscard]] const TaskMonitor& task() const { return monitor_; }
  [[nodiscard]] const Simulation& simulation() const { return simulation_; }

  /// Records the end (a `session` event and session.json's end keys), and waits until it is on disk.
  /// `reason`: completed, timeout, signal or error.
  void finish(const std::string& reason);

  /// The line for the parent (sim_manager) once the session's data stopped being written:
  /// "data incomplete reason=<one line of text>\n". Given once; "" before a failure, after it was given,
  /// and without a writer.
  [[nodiscard]] std::string take_data_notice();

 private:
  void record_task_events();

  Simulation& simulation_;
  TaskMonitor monitor_;
  StudyCodes codes_;
  SessionWriter* writer_;
  bool data_notice_given_ = false;
};

}  // namespace rfbsim::sim
