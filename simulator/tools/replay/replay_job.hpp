// SPDX-License-Identifier: GPL-2.0-or-later
// replay_session: sim_replay's whole job on one session folder, as a function (the command line prints its
// result; bench_replay times it). Reads the log, refuses a log this build cannot repeat (unless forced),
// rebuilds the world, drives it with the recorded inputs to the recorded end, optionally draws every
// frame into a video, and compares the replay's trajectories and outcome with the log.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "record/session_log.hpp"
#include "render/scene_builder.hpp"
#include "replay_cli.hpp"

namespace rfbsim::replay {

/// Exit statuses of sim_replay (docs/replay.md).
inline constexpr int kExitMatch = 0;    ///< the replay matches the log (and the video was written)
inline constexpr int kExitFailure = 1;  ///< something failed: GL, the encoder, a write
inline constexpr int kExitRefused = 2;  ///< unreadable session data, or a log this build cannot repeat
inline constexpr int kExitDiffers = 3;  ///< the replay departed from the log

/// What a replay found, and what it cost.
struct ReplayResult {
  int exit_status = kExitFailure;
  std::vector<std::string> report;    ///< the verdict and what was written (for stdout)
  std::vector<std::string> warnings;  ///< e.g. a mismatch passed over with --force (for stderr)
  std::string error;                  ///< why it failed or was refused (for stderr); empty otherwise

  std::uint64_t end_tick = 0;  ///< ticks replayed
  double simulated_s = 0.0;    ///< end_tick / tick_hz
  std::size_t rows = 0;        ///< trajectory rows that matched
  double wall_s = 0.0;         ///< wall time of the replay loop (stepping, drawing, encoding)
  std::int64_t frames = 0;     ///< video frames written
  std::vector<double> render_ms;  ///< per frame: paint (scene + HUD) and read back, ms
  std::vector<double> encode_ms;  ///< per frame: convert to YUV and encode (and write what the encoder gave), ms
  std::string renderer;        ///< GL renderer, with --video
  std::string encoder;         ///< H.264 encoder, with --video
  std::int64_t video_bytes = 0;
};

/// Called now and then during the replay with the simulated seconds done and in all.
using ProgressFn = std::function<void(double done_s, double total_s)>;

/// How the video draws `meta`'s session under `view`: the participant's camera as session.json's `camera`
/// recorded it (third person for files older than the key), or the top view fitted to the recorded frame.
sim::SceneStyle video_style(View view, const sim::SessionMeta& meta);

/// Replays `options.session_dir` as `options` say (a watcher's folder of the video condition is refused: it
/// recorded nothing to replay). Never throws: every failure is a result with its exit
/// status and message.
ReplayResult replay_session(const ReplayOptions& options, const ProgressFn& progress = {});

}  // namespace rfbsim::replay
