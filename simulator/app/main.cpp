// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb: one participant's simulation, rendered off-screen and served to the browser.
//
// The main thread is the simulation thread: it owns the GL context, steps the world at a fixed rate,
// and renders at the frame rate only while someone is watching. librfbsim's own thread does the network.
// With --replay, a recorded session is shown instead (app/replay_loop.cpp), through the same serving parts
// (app/serving.hpp).
#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "app/frame_painter.hpp"
#include "app/frame_schedule.hpp"
#include "app/options.hpp"
#include "app/parent_pipe.hpp"
#include "app/replay_loop.hpp"
#include "app/ros_link.hpp"
#include "app/ros_setup.hpp"
#include "app/serving.hpp"
#include "app/session_setup.hpp"
#include "app/simulation.hpp"
#include "app/stream_status.hpp"
#include "app/study_session.hpp"
#include "contract/ready_line.hpp"
#include "record/digest.hpp"
#include "record/session_writer.hpp"
#include "replay/recording.hpp"
#include "rfbsim/log.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "rfbsim/server.hpp"
#include "scenario/scenario.hpp"
#include "world/fixed_step_clock.hpp"

namespace {

using rfbsim::sim::check_ready_fd;
using rfbsim::sim::ClientChanges;
using rfbsim::sim::report_outcome;
using rfbsim::sim::report_ready;
using rfbsim::sim::server_options_of;
using rfbsim::sim::StatusBoard;
using rfbsim::sim::StreamReporter;
using rfbsim::sim::write_line;

std::atomic<bool> g_stop{false};

void request_stop(int /*signal*/) { g_stop = true; }

void install_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A reader that went away (sim_manager's ready pipe, a client socket) must show up as EPIPE from the
  // write, which we report, not as a signal that ends the process without a word.
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGPIPE, &ignore, nullptr);
}

// What the command line asks to build.
rfbsim::sim::SessionSetup setup_of(const rfbsim::sim::SimOptions& options) {
  rfbsim::sim::SessionSetup setup;
  setup.scenario = options.scenario;
  setup.seed = options.seed;
  setup.tick_hz = options.tick_hz;
  if (options.time_limit) setup.time_limit = *options.time_limit;
  if (options.end_grace) setup.end_grace = *options.end_grace;
  const std::pair<const char*, const std::optional<std::string>*> poses[] = {
      {"avatar_start", &options.avatar_start}, {"avatar_goal", &options.avatar_goal},
      {"robot_start", &options.robot_start}, {"robot_goal", &options.robot_goal}};
  for (const auto& [name, value] : poses) {
    if (*value) setup.parameters.emplace_back(name, **value);
  }
  if (options.crowd) setup.parameters.emplace_back("crowd", std::to_string(*options.crowd));
  if (options.robot_control) setup.parameters.emplace_back("robot_control", *options.robot_control);
  if (options.camera) setup.parameters.emplace_back("camera", *options.camera);
  return setup;
}

// The robot's state changes of the last tick, one log line each ("[robot] 12.35 s moving: ...").
void log_robot_events(const rfbsim::sim::World& world, double dt) {
  for (const rfbsim::sim::RobotEvent& event : world.robot_events) {
    rfbsim::log::info("robot", "%.2f s %s: %s", static_cast<double>(event.tick) * dt,
                      rfbsim::sim::robot_state_name(event.state), event.detail.c_str());
  }
}

// Tests only: RFBSIM_TEST_FAIL_WRITES_AFTER=<bytes> makes the session data's writes fail with ENOSPC after that
// many appended bytes, so that a full disk can be tested without one (record/sync_queue.hpp's WriteFaults).
rfbsim::sim::SessionWriterOptions writer_options_from_environment() {
  rfbsim::sim::SessionWriterOptions options;
  const char* limit = std::getenv("RFBSIM_TEST_FAIL_WRITES_AFTER");
  if (limit == nullptr) return options;
  char* end = nullptr;
  errno = 0;
  const unsigned long long bytes = std::strtoull(limit, &end, 10);
  if (*limit == '\0' || *end != '\0' || errno != 0) {
    throw std::runtime_error(std::string("RFBSIM_TEST_FAIL_WRITES_AFTER: '") + limit + "' is not a byte count");
  }
  options.faults.fail_after_bytes = bytes;
  rfbsim::log::info("sim_rfb", "test fault: session data writes fail after %llu bytes", bytes);
  return options;
}

int run(const rfbsim::sim::SimOptions& options) {
  using Clock = std::chrono::steady_clock;
  namespace sim = rfbsim::sim;

  if (options.ready_fd) check_ready_fd(*options.ready_fd);
  // The scenario first: a broken one ends the program before anything listens.
  sim::PreparedSession prepared = sim::prepare_session(setup_of(options));
  sim::Simulation& simulation = *prepared.simulation;
  if (!options.scenario.empty()) {
    rfbsim::log::info("sim_rfb", "scenario %s (%s), seed %llu, %zu people", prepared.info.scenario.c_str(),
                      prepared.info.scenario_file.c_str(), static_cast<unsigned long long>(prepared.info.seed),
                      simulation.world().people.size());
  }
  std::unique_ptr<sim::RosLink> ros_link = sim::open_ros_link(options);
  const sim::RobotStack* robot_stack = simulation.robot_stack();
  if (robot_stack && robot_stack->control() == sim::RobotControl::kExternal && !options.rosbridge_port &&
      options.rosbridge_connect.empty()) {
    rfbsim::log::warn("ros",
                      "warning: the robot is under external control but no rosbridge is configured "
                      "(--rosbridge-port or --rosbridge-connect): nothing can drive it, and it will stand still");
  }
  // Session data from the first tick on, when asked for.
  std::unique_ptr<sim::SessionWriter> writer;
  if (!options.data_dir.empty()) {
    sim::SessionInfo info = prepared.info;
    if (ros_link) {
      if (ros_link->writes_bag()) info.ros_bag = "session.mcap";
      info.ros_bridge = ros_link->bridge_description();
      info.ros_namespace = options.ros_namespace;
    }
    info.uid = options.uid;
    info.fps = options.fps;
    info.trajectory_hz = options.trajectory_hz;
    info.width = options.width;
    info.height = options.height;
    if (!options.code_success.empty() || !options.code_timeout.empty()) {
      info.codes = std::make_pair(options.code_success, options.code_timeout);
    }
    writer = std::make_unique<sim::SessionWriter>(options.data_dir, std::move(info), simulation.world(),
                                                  writer_options_from_environment());
    // The study's events also go to ROS's /events, and into the bag.
    if (ros_link) {
      writer->set_event_listener([&ros_link](std::uint64_t tick, const std::string& line) { ros_link->event(tick, line); });
    }
  }
  if (ros_link) ros_link->sample(simulation.world(), simulation.robot_stack());  // tick 0: /map, the scene, the start
  sim::StudySession study(simulation, prepared.task, {options.code_success, options.code_timeout}, writer.get());
  // A recording that stopped (a full disk) is told to the parent once, on the ready pipe; the session goes on.
  const auto report_data_notice = [&] {
    const std::string notice = study.take_data_notice();
    if (notice.empty() || !options.ready_fd) return;
    const std::string error = write_line(*options.ready_fd, notice);
    if (!error.empty()) rfbsim::log::warn("sim_rfb", "cannot report incomplete data to the parent: %s", error.c_str());
  };
  const std::string address_key = sim::address_hash_key();

  StatusBoard status;
  ClientChanges client_changes;
  const sim::Picture picture{options.width, options.height, options.fps};
  rfbsim::Server server(server_options_of(options, picture, status, client_changes, address_key));

  rfbsim::OffscreenGL gl(gl_options_of(options, picture));
  rfbsim::log::info("sim_rfb", "rendering with %s", gl.renderer().c_str());
  rfbsim::log::info("sim_rfb", "picture encoding %s, %d frames per second while watched", options.codec.c_str(),
                    options.fps);

  sim::FixedStepClock clock(std::chrono::nanoseconds(1'000'000'000LL / options.tick_hz));
  const auto frame_interval = std::chrono::nanoseconds(1'000'000'000LL / options.fps);
  sim::SceneStyle scene_style;
  scene_style.debug_overlay = options.debug_overlay;
  scene_style.camera = prepared.camera;
  std::uint64_t frames_rendered = 0;
  sim::FramePainter painter(gl, scene_style);
  // Draws the world and the HUD and hands the frame to the server, unless it would look as the last one (which
  // the server keeps showing).
  const auto draw_if_changed = [&] {
    if (!painter.paint(simulation.world(), study.text())) return;
    server.submit(gl.read_frame());
    ++frames_rendered;
  };
  // One frame before anyone watches, so that the first update a viewer gets is the scene, not black.
  draw_if_changed();

  // Readers of /status.json never see an empty document, even before the first tick.
  status.publish(sim::status_json(simulation.world(), 0, 0));
  // The parent's line first: if it cannot be told, we are not ready, and stdout should not say we are.
  if (options.ready_fd) report_ready(*options.ready_fd, server);
  if (ros_link && ros_link->server_port()) {
    std::printf("sim_rfb rosbridge: ws://%s:%d/\n", sim::url_host(options.rosbridge_bind).c_str(),
                *ros_link->server_port());
  }
  std::printf("sim_rfb ready: %s\n", server.url().c_str());
  std::fflush(stdout);

  std::optional<StreamReporter> stream_reporter;
  if (options.ready_fd) stream_reporter.emplace(*options.ready_fd);
  auto last = Clock::now();
  sim::FrameSchedule frames(frame_interval);
  bool outcome_reported = false;
  bool bag_failure_told = false;
  std::string end_reason = "signal";
  while (!g_stop) {
    const auto now = Clock::now();
    const int ticks = clock.advance(now - last);
    last = now;

    // Viewers and input drained now are recorded at this tick and take effect from the next one.
    for (const ClientChanges::Change& change : client_changes.take()) {
      if (change.connected) {
        // A researcher's watch connection (marked view-only by sim_manager's relay) must not start the clock.
        study.client_connected(change.client.id, sim::hash_address(address_key, change.client.address),
                               change.client.websocket,
                               change.client.view_only ? sim::ViewerRole::kWatcher : sim::ViewerRole::kParticipant);
      } else {
        study.client_disconnected(change.client.id, sim::hash_address(address_key, change.client.address),
                                  change.client.websocket);
      }
    }
    const sim::ControlState controls_before = simulation.controls();
    for (const rfbsim::InputEvent& event : server.poll_input()) {
      if (event.kind == rfbsim::InputEvent::Kind::Key) {
        study.key(event.keysym, event.down, event.client_id);
      } else {
        study.pointer(event.x, event.y, event.buttons, event.client_id);
      }
    }
    // A held key's repeats change nothing: only a press or release that did is worth an early frame.
    if (simulation.controls() != controls_before) frames.controls_changed();
    // An external controller's commands, like keys, are recorded at this tick and drive from the next. Only the
    // last one taken now can matter (each replaces the one before), so only it is recorded: a controller that
    // floods /cmd_vel costs no disk, and the replay is the same.
    if (ros_link) {
      std::vector<sim::RobotCommand> commands = ros_link->take_commands();
      if (!commands.empty() && !study.robot_command(commands.back().v, commands.back().w, commands.back().source)) {
        for (const sim::RobotCommand& command : commands) {
          ros_link->warn_ignored(command, "the robot is under built-in control; /cmd_vel is ignored "
                                          "(start the session with robot_control external)");
        }
      }
      // A bag that stopped (a full disk) is told once, in the log (session.log under sim_manager). It is not the
      // parent's "data incomplete", which is about the files the study's tables come from (trajectories.csv,
      // events.jsonl): those may well go on while the larger bag cannot.
      if (const auto failure = ros_link->bag_failure(); failure && !bag_failure_told) {
        bag_failure_told = true;
        rfbsim::log::info("ros", "session.mcap stopped growing: %s (the session and its other files go on)",
                          failure->c_str());
      }
    }
    for (int i = 0; i < ticks && !study.over(); ++i) {
      study.step();
      log_robot_events(simulation.world(), simulation.params().dt);
      if (ros_link) ros_link->sample(simulation.world(), simulation.robot_stack());
    }
    // The outcome goes to the parent (sim_manager tells the survey) as soon as it is reached.
    if (!outcome_reported && study.outcome() != sim::TaskOutcome::None) {
      outcome_reported = true;
      const char* outcome = sim::task_outcome_name(study.outcome());
      rfbsim::log::info("task", "%.2f s outcome %s", simulation.world().time, outcome);
      if (options.ready_fd) {
        report_outcome(*options.ready_fd, study.outcome() == sim::TaskOutcome::Completed
                                              ? rfbsim::contract::TaskEnd::kCompleted
                                              : rfbsim::contract::TaskEnd::kTimeout);
      }
    }
    if (study.over()) {
      end_reason = sim::task_outcome_name(study.outcome());
      break;
    }
    if (writer) writer->flush_if_due();
    if (ros_link) ros_link->flush_if_due();
    report_data_notice();
    const int clients = server.client_count();
    if (ticks > 0 && !options.rfb_only) {
      status.publish(
          sim::status_json(simulation.world(), clients, frames_rendered, sim::streams_json(server.client_streams())));
    }
    if (stream_reporter) stream_reporter->update(now, clients, server);

    // Render only for a viewer: at the frame rate, and early for a change of controls (FrameSchedule).
    if (frames.render_now(now, ticks, clients > 0)) draw_if_changed();
    auto wake = now + clock.until_next_step();
    if (clients > 0) wake = std::min(wake, frames.next_frame());
    std::this_thread::sleep_until(wake);
  }
  study.finish(end_reason);
  if (ros_link) ros_link->finish();  // after the end's events, which the bag records too
  report_data_notice();  // the end's own writes may have been the ones that failed
  if (options.ready_fd) ::close(*options.ready_fd);
  rfbsim::log::flush_suppressed();  // what the rate limit held back is counted before the last line
  rfbsim::log::info("sim_rfb", "stopping after %llu ticks, %llu frames (%s)",
                    static_cast<unsigned long long>(simulation.world().tick),
                    static_cast<unsigned long long>(frames_rendered), end_reason.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  const auto parsed = rfbsim::sim::parse_sim_options(args);
  if (!parsed.error.empty()) {
    std::fprintf(stderr, "sim_rfb: %s\n%s", parsed.error.c_str(), rfbsim::sim::sim_usage().c_str());
    return 2;
  }
  if (parsed.options.help) {
    std::fputs(rfbsim::sim::sim_usage().c_str(), stdout);
    return 0;
  }
  rfbsim::log::set_level(parsed.options.log_level);  // checked by the parser
  install_signal_handlers();
  try {
    return parsed.options.replay.empty() ? run(parsed.options) : rfbsim::sim::run_replay(parsed.options, g_stop);
  } catch (const rfbsim::replay::RecordingError& error) {
    std::fprintf(stderr, "sim_rfb: replay: %s\n", error.what());
    return 2;
  } catch (const rfbsim::sim::SessionLogError& error) {  // a recording whose inputs turn out out of order
    std::fprintf(stderr, "sim_rfb: replay: %s\n", error.what());
    return 2;
  } catch (const rfbsim::sim::ScenarioError& error) {
    std::fprintf(stderr, "sim_rfb: scenario error: %s\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "sim_rfb: error: %s\n", error.what());
    return 1;
  }
}
