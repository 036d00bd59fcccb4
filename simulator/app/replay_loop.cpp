// SPDX-License-Identifier: GPL-2.0-or-later
// run_replay: open, serve, play, hold, end.
#include "app/replay_loop.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "app/frame_painter.hpp"
#include "app/frame_schedule.hpp"
#include "app/parent_pipe.hpp"
#include "app/serving.hpp"
#include "app/simulation.hpp"
#include "app/stream_status.hpp"
#include "app/watch_record.hpp"
#include "app/watched_replay.hpp"
#include "record/digest.hpp"
#include "replay/recording.hpp"
#include "rfbsim/log.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "rfbsim/server.hpp"
#include "world/fixed_step_clock.hpp"

namespace rfbsim::sim {

namespace {

// How long the recording's last picture stays after its end when --end-grace does not say, s: long enough to
// see that it ended, short beside the recording itself.
constexpr int kWatchedHoldS = 3;
// With a completion code of the watcher's own (--code-success), as long as a live session shows its code by
// default: time to copy it where the page is not inside a survey that hears it.
constexpr int kWatchedCodeHoldS = 15;

}  // namespace

// sim_rfb --replay (docs/replay.md): a recorded session shown tick for tick at its own pace, view-only,
// through the same server, painter and ready pipe as a live one. It starts with the first viewer, so that the
// watcher sees it from its beginning; at its end the parent hears "outcome watched", and the last picture stays
// for --end-grace seconds or until the last viewer leaves. The watcher's keys and pointer are dropped by the
// server (view-only) and never reach the replay or any record.
int run_replay(const SimOptions& options, const std::atomic<bool>& stop) {
  using Clock = std::chrono::steady_clock;

  if (options.ready_fd) check_ready_fd(*options.ready_fd);
  // The recording first: a bad one ends the program before anything listens or is written.
  if (!options.data_dir.empty()) check_watch_data_dir(options.data_dir, options.replay);
  WatchedReplay replay(options.replay);
  const SessionMeta& meta = replay.meta();
  const Picture picture{meta.frame_width, meta.frame_height, meta.fps};  // what the walker saw
  if (picture.width < 16 || picture.height < 16 || picture.width > 7680 || picture.height > 4320 || picture.fps < 1 ||
      picture.fps > 240) {
    throw rfbsim::replay::RecordingError((replay.dir() / "session.json").string() + ": a frame of " +
                                         std::to_string(picture.width) + "x" + std::to_string(picture.height) +
                                         " at " + std::to_string(picture.fps) + " fps cannot be shown");
  }
  // Not the recording's folder or uid: this log is the watcher's, and the folder's name holds the walker's uid.
  rfbsim::log::info("sim_rfb", "replaying a session of scenario %s: %llu ticks at %d Hz, %dx%d at %d fps",
                    meta.scenario.c_str(), static_cast<unsigned long long>(replay.end_tick()), meta.tick_hz,
                    picture.width, picture.height, picture.fps);
  replay.set_watcher_code(options.code_success);
  const std::string address_key = address_hash_key();
  std::unique_ptr<WatchRecord> record;
  if (!options.data_dir.empty()) {
    record = std::make_unique<WatchRecord>(options.data_dir, options.uid, meta, options.yoked_to, address_key);
  }

  StatusBoard status;
  ClientChanges client_changes;
  rfbsim::ServerOptions server_options = server_options_of(options, picture, status, client_changes, address_key);
  server_options.view_only = true;
  rfbsim::Server server(std::move(server_options));

  rfbsim::OffscreenGL gl(gl_options_of(options, picture));
  rfbsim::log::info("sim_rfb", "rendering with %s", gl.renderer().c_str());

  FixedStepClock clock(std::chrono::nanoseconds(1'000'000'000LL / meta.tick_hz));
  SceneStyle scene_style;
  scene_style.debug_overlay = options.debug_overlay;
  // The watcher sees the view the walker had (session.json's camera: first or third person).
  scene_style.camera = meta.camera;
  FramePainter painter(gl, scene_style);
  std::uint64_t frames_rendered = 0;
  const auto draw = [&](bool always) {
    if (!painter.paint(replay.world(), replay.text(), always)) return;
    server.submit(gl.read_frame());
    ++frames_rendered;
  };
  const auto publish = [&](int clients) {
    if (options.rfb_only) return;
    status.publish(with_status_member(
        status_json(replay.world(), clients, frames_rendered, streams_json(server.client_streams())),
        replay.status_member()));
  };
  draw(true);  // the recording's first tick, before anyone watches
  publish(0);
  if (options.ready_fd) report_ready(*options.ready_fd, server);
  std::printf("sim_rfb ready: %s\n", server.url().c_str());
  std::fflush(stdout);

  std::optional<StreamReporter> stream_reporter;
  if (options.ready_fd) stream_reporter.emplace(*options.ready_fd);
  FrameSchedule frames(std::chrono::nanoseconds(1'000'000'000LL / picture.fps));
  const auto hold = std::chrono::seconds(
      options.end_grace.value_or(options.code_success.empty() ? kWatchedHoldS : kWatchedCodeHoldS));
  bool playing = false;
  std::optional<Clock::time_point> hold_until;  // set at the recording's end
  std::string end_reason = "signal";
  auto last = Clock::now();
  while (!stop) {
    const auto now = Clock::now();
    const int ticks = clock.advance(now - last);
    last = now;

    for (const ClientChanges::Change& change : client_changes.take()) {
      if (!change.connected) continue;
      if (record) record->viewer_connected();
      if (!playing) rfbsim::log::info("sim_rfb", "the first viewer came: the recording plays");
      playing = true;
    }
    // The server is view-only and hands over nothing; anything that came anyway is dropped unread.
    (void)server.poll_input();

    if (playing && !replay.ended() && replay.advance(ticks)) {
      // The last picture before the line, so that a parent (or a test) that asks after it sees the end.
      draw(true);
      end_reason = "watched";
      rfbsim::log::info("task", "%.2f s outcome watched (the recording's end)", replay.world().time);
      if (options.ready_fd) report_outcome(*options.ready_fd, contract::TaskEnd::kWatched);
      hold_until = now + hold;
      publish(server.client_count());
    }
    const int clients = server.client_count();
    if (hold_until && (now >= *hold_until || clients == 0)) break;
    if (playing && ticks > 0 && !replay.ended()) publish(clients);
    if (stream_reporter) stream_reporter->update(now, clients, server);

    if (!replay.ended() && frames.render_now(now, ticks, clients > 0)) draw(false);
    auto wake = now + clock.until_next_step();
    if (clients > 0) wake = std::min(wake, frames.next_frame());
    if (hold_until) wake = std::min(wake, *hold_until);
    std::this_thread::sleep_until(wake);
  }
  if (record) {
    const std::string error = record->finish(end_reason, replay.world().tick, end_reason == "watched");
    if (!error.empty()) rfbsim::log::warn("sim_rfb", "cannot record the end of the watching: %s", error.c_str());
  }
  if (options.ready_fd) ::close(*options.ready_fd);
  rfbsim::log::flush_suppressed();
  rfbsim::log::info("sim_rfb", "stopping the replay at tick %llu of %llu, %llu frames (%s)",
                    static_cast<unsigned long long>(replay.world().tick),
                    static_cast<unsigned long long>(replay.end_tick()),
                    static_cast<unsigned long long>(frames_rendered), end_reason.c_str());
  return 0;
}

}  // namespace rfbsim::sim
