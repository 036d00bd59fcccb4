// SPDX-License-Identifier: GPL-2.0-or-later
// StudySession: inputs, the tick, the task and the record, in that order.
#include "app/study_session.hpp"

#include "contract/ready_line.hpp"

namespace rfbsim::sim {

const char* viewer_role_name(ViewerRole role) { return role == ViewerRole::kWatcher ? "watcher" : "participant"; }

StudySession::StudySession(Simulation& simulation, TaskSpec task, StudyCodes codes, SessionWriter* writer)
    : simulation_(simulation), monitor_(std::move(task), simulation.params().dt), codes_(std::move(codes)), writer_(writer) {
  if (writer_ == nullptr) return;
  writer_->event(simulation_.world().tick, "session", {{"event", "start"}});
  writer_->sample(simulation_.world());
  writer_->checkpoint();  // the start is on disk before anyone sees the world
}

void StudySession::key(std::uint32_t keysym, bool down, int client) {
  if (writer_ != nullptr) {
    writer_->event(simulation_.world().tick, "key", {{"keysym", keysym}, {"down", down}, {"client", client}});
  }
  simulation_.apply_key(keysym, down);
}

bool StudySession::robot_command(double v, double w, const std::string& source) {
  const RobotStack* robot = simulation_.robot_stack();
  if (robot == nullptr || robot->control() != RobotControl::kExternal) return false;
  if (writer_ != nullptr) {
    writer_->event(simulation_.world().tick, "robot_command", {{"v", v}, {"w", w}, {"source", source}});
  }
  return simulation_.command_robot(v, w);
}

void StudySession::pointer(int x, int y, int buttons, int client) {
  if (writer_ == nullptr) return;
  writer_->event(simulation_.world().tick, "pointer", {{"x", x}, {"y", y}, {"buttons", buttons}, {"client", client}});
}

void StudySession::client_connected(int client, const std::string& address_hash, bool websocket, ViewerRole role) {
  if (writer_ != nullptr) {
    // The role only when it is a watcher: participants' events stay as they were, so older logs replay alike.
    nlohmann::ordered_json fields = {
        {"event", "connect"}, {"client", client}, {"address", address_hash}, {"websocket", websocket}};
    if (role == ViewerRole::kWatcher) fields["role"] = viewer_role_name(role);
    writer_->event(simulation_.world().tick, "client", fields);
  }
  // The clock starts when the participant can first see the world, not when the process started, and not
  // when a researcher opened the session to watch it (before the participant came, or without one at all).
  if (role == ViewerRole::kParticipant) monitor_.start_timer(simulation_.world());
  record_task_events();
}

void StudySession::client_disconnected(int client, const std::string& address_hash, bool websocket) {
  if (writer_ == nullptr) return;
  writer_->event(simulation_.world().tick, "client",
                 {{"event", "disconnect"}, {"client", client}, {"address", address_hash}, {"websocket", websocket}});
}

void StudySession::step() {
  simulation_.step();
  monitor_.observe(simulation_.world());
  if (writer_ != nullptr) {
    writer_->sample(simulation_.world());
    writer_->world_events(simulation_.world());
  }
  record_task_events();
}

void StudySession::record_task_events() {
  if (writer_ == nullptr) {
    monitor_.clear_events();
    return;
  }
  const TaskSpec& spec = monitor_.spec();
  for (const TaskEvent& e : monitor_.events()) {
    const auto step_fields = [&](const char* what) {
      const TaskStep& step = spec.steps[static_cast<std::size_t>(e.index)];
      return nlohmann::ordered_json{{"event", what}, {"index", e.index}, {"task", task_type_name(step.type)},
                                    {"text", task_step_text(step)}};
    };
    switch (e.kind) {
      case TaskEvent::Kind::TimerStarted: writer_->event(e.tick, "timer", {{"event", "started"}}); break;
      case TaskEvent::Kind::StepStarted: writer_->event(e.tick, "task", step_fields("started")); break;
      case TaskEvent::Kind::StepDone:
        writer_->event(e.tick, "task", step_fields("done"));
        writer_->task_done(task_type_name(spec.steps[static_cast<std::size_t>(e.index)].type), e.tick);
        break;
      case TaskEvent::Kind::Outcome:
        writer_->event(e.tick, "outcome", {{"outcome", task_outcome_name(e.outcome)}, {"code", outcome_code()}});
        writer_->outcome(task_outcome_name(e.outcome), outcome_code(), e.tick);
        break;
    }
  }
  // Each task event (the clock's start, a step, the outcome) goes to disk at once, with what led to it.
  if (!monitor_.events().empty()) writer_->checkpoint();
  monitor_.clear_events();
}

bool StudySession::over() const {
  const auto at = monitor_.outcome_tick();
  if (!at) return false;
  const double since = static_cast<double>(simulation_.world().tick - *at) * simulation_.params().dt;
  return since >= monitor_.spec().end_grace - 1e-9;
}

std::string StudySession::outcome_code() const {
  switch (monitor_.outcome()) {
    case TaskOutcome::Completed: return codes_.success;
    case TaskOutcome::Timeout: return codes_.timeout;
    case TaskOutcome::None: break;
  }
  return "";
}

void StudySession::finish(const std::string& reason) {
  if (writer_ == nullptr) return;
  writer_->event(simulation_.world().tick, "session", {{"event", "end"}, {"reason", reason}});
  writer_->finish({simulation_.world().tick, reason});
}

std::string StudySession::take_data_notice() {
  if (writer_ == nullptr || data_notice_given_) return "";
  const std::optional<std::string> failure = writer_->failure();
  if (!failure) return "";
  data_notice_given_ = true;
  return contract::data_incomplete_line(*failure);
}

}  // namespace rfbsim::sim
