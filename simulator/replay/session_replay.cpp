// SPDX-License-Identifier: GPL-2.0-or-later
// SessionReplay: the recorded inputs, applied at their ticks.
#include "replay/session_replay.hpp"

#include <charconv>
#include <limits>
#include <stdexcept>

namespace rfbsim::replay {

namespace {

// A recorded integer that must fit an int (client ids, pixels, button masks).
int small_int(const sim::Event& event, const char* key) {
  const std::int64_t value = event.integer(key);
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max()) {
    throw sim::SessionLogError("events.jsonl: " + event.type + " event at tick " + std::to_string(event.tick) + ": '" +
                               key + "' out of range");
  }
  return static_cast<int>(value);
}

}  // namespace

sim::SessionSetup setup_of(const sim::SessionMeta& meta) {
  sim::SessionSetup setup;
  setup.scenario = meta.scenario_file;
  // The parameters as sim_rfb was given them: "seed" only when one was (it then replaces a crowd's own seed
  // too, so the recorded master seed alone would not say which crowd ran).
  for (const auto& [name, value] : meta.parameters) {
    if (name == "seed") {
      std::uint64_t seed = 0;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), seed);
      if (ec != std::errc() || end != value.data() + value.size() || value.empty()) {
        throw sim::SessionLogError("session.json: key 'parameters.seed': expected a decimal 64-bit seed, got '" +
                                   value + "'");
      }
      setup.seed = seed;
    } else {
      setup.parameters.emplace_back(name, value);
    }
  }
  setup.tick_hz = meta.tick_hz;
  setup.time_limit = meta.time_limit_s;
  setup.end_grace = meta.end_grace_s;
  return setup;
}

std::uint64_t recorded_end_tick(const sim::SessionLog& log) {
  if (log.meta.end_tick) return *log.meta.end_tick;
  return log.trajectory.empty() ? 0 : log.trajectory.back().tick;
}

SessionReplay::SessionReplay(const sim::SessionLog& log, sim::PreparedSession prepared, const std::filesystem::path& out_dir)
    : log_(log), out_dir_(out_dir), end_tick_(recorded_end_tick(log)), simulation_(std::move(prepared.simulation)) {
  const sim::SessionMeta& meta = log.meta;
  // The replay's own session.json says what the recording's said about who and how it was shown.
  sim::SessionInfo info = std::move(prepared.info);
  info.uid = meta.uid;
  info.fps = meta.fps;
  info.trajectory_hz = meta.trajectory_hz;
  info.width = meta.frame_width;
  info.height = meta.frame_height;
  if (meta.success_code || meta.timeout_code) {
    info.codes = std::make_pair(meta.success_code.value_or(""), meta.timeout_code.value_or(""));
  }
  // A live replay (sim_rfb --replay) records nothing: its watcher's actions are not the recording's inputs.
  if (!out_dir_.empty()) writer_ = std::make_unique<sim::SessionWriter>(out_dir_, std::move(info), simulation_->world());
  study_ = std::make_unique<sim::StudySession>(*simulation_, std::move(prepared.task),
                                               sim::StudyCodes{meta.success_code.value_or(""), meta.timeout_code.value_or("")},
                                               writer_.get());
}

SessionReplay::~SessionReplay() = default;

void SessionReplay::apply(const sim::Event& event) {
  // The inputs, exactly as sim_rfb hands them to StudySession; everything else in the log (contacts, task
  // steps, the robot's states) is what the replay must produce by itself.
  if (event.type == "key") {
    const std::int64_t keysym = event.integer("keysym");
    if (keysym < 0 || keysym > std::numeric_limits<std::uint32_t>::max()) {
      throw sim::SessionLogError("events.jsonl: key event at tick " + std::to_string(event.tick) + ": keysym out of range");
    }
    study_->key(static_cast<std::uint32_t>(keysym), event.flag("down"), small_int(event, "client"));
  } else if (event.type == "robot_command") {
    // An external controller's command (docs/ros.md): the replay drives the robot as it was driven.
    const auto number = [&event](const char* key) {
      const auto found = event.fields.find(key);
      if (found == event.fields.end() || !found->is_number()) {
        throw sim::SessionLogError("events.jsonl: robot_command event at tick " + std::to_string(event.tick) +
                                   ": '" + key + "' is not a number");
      }
      return found->get<double>();
    };
    study_->robot_command(number("v"), number("w"), event.text("source"));
  } else if (event.type == "pointer") {
    study_->pointer(small_int(event, "x"), small_int(event, "y"), small_int(event, "buttons"), small_int(event, "client"));
  } else if (event.type == "client") {
    const std::string& what = event.text("event");
    if (what == "connect") {
      // A watcher's connect (docs/data.md: "role":"watcher") did not start the clock live, so not here either.
      const auto role = event.text("role") == "watcher" ? sim::ViewerRole::kWatcher : sim::ViewerRole::kParticipant;
      study_->client_connected(small_int(event, "client"), event.text("address"), event.flag("websocket"), role);
    } else if (what == "disconnect") {
      study_->client_disconnected(small_int(event, "client"), event.text("address"), event.flag("websocket"));
    } else {
      return;
    }
  } else {
    return;
  }
  ++inputs_applied_;
}

void SessionReplay::apply_inputs() {
  const std::uint64_t tick = world().tick;
  const std::vector<sim::Event>& events = log_.events;
  for (; next_event_ < events.size() && events[next_event_].tick <= tick; ++next_event_) {
    const sim::Event& event = events[next_event_];
    if (event.tick < tick && (event.type == "key" || event.type == "pointer" || event.type == "client" ||
                                  event.type == "robot_command")) {
      throw sim::SessionLogError((log_.dir / "events.jsonl").string() + ": a " + event.type + " event at tick " +
                                 std::to_string(event.tick) + " comes after events of tick " + std::to_string(tick) +
                                 ": events are not in tick order");
    }
    apply(event);
  }
}

void SessionReplay::step() {
  apply_inputs();
  study_->step();
  if (writer_) writer_->flush_if_due();  // as sim_rfb does: a long replay does not hold its whole record in memory
}

void SessionReplay::finish() {
  apply_inputs();
  study_->finish(log_.meta.end_reason.value_or("error"));
  if (writer_) writer_->flush();
}

}  // namespace rfbsim::replay
