// SPDX-License-Identifier: GPL-2.0-or-later
// replay_session: read, check provenance, rebuild, replay (and film), compare.
#include "replay_job.hpp"

#include <stdlib.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <nlohmann/json.hpp>

#include "app/frame_painter.hpp"
#include "app/session_setup.hpp"
#include "replay/provenance.hpp"
#include "replay/recording.hpp"
#include "record/session_log.hpp"
#include "rfbsim/offscreen_gl.hpp"
#include "replay/session_replay.hpp"
#include "trajectory_diff.hpp"
#include "video_writer.hpp"
#include "watcher_session.hpp"

namespace rfbsim::replay {

namespace {

using Clock = std::chrono::steady_clock;

// A failure with its exit status, thrown inside the job and turned into the result at its edge.
struct JobFailure {
  int status;
  std::string message;
};

// The folder the replay records into: --out-dir (kept), or a fresh temporary one (removed at the end).
class OutputFolder {
 public:
  explicit OutputFolder(const ReplayOptions& options) {
    std::error_code ec;
    if (options.out_dir) {
      path_ = *options.out_dir;
      if (std::filesystem::exists(path_, ec) &&
          std::filesystem::equivalent(path_, options.session_dir, ec)) {
        throw JobFailure{kExitRefused, "--out-dir " + path_.string() + " is the session's own folder: give another"};
      }
      for (const char* name : {"session.json", "trajectories.csv", "events.jsonl"}) {
        if (std::filesystem::exists(path_ / name, ec)) {
          throw JobFailure{kExitRefused, "--out-dir " + path_.string() + " already holds session data (" + name +
                                             "): give a new or empty folder"};
        }
      }
      return;
    }
    std::string pattern = (std::filesystem::temp_directory_path(ec) / "sim_replay.XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw JobFailure{kExitFailure, "cannot make a temporary folder in " + std::filesystem::temp_directory_path(ec).string()};
    }
    path_ = pattern;
    temporary_ = true;
  }
  ~OutputFolder() {
    std::error_code ec;
    if (temporary_) std::filesystem::remove_all(path_, ec);
  }
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] bool kept() const { return !temporary_; }

 private:
  std::filesystem::path path_;
  bool temporary_ = false;
};

// Refuses (or with --force, warns about) each provenance mismatch.
void check_provenance(const std::vector<ProvenanceMismatch>& mismatches, const ReplayOptions& options,
                      const std::filesystem::path& session_json, ReplayResult& result) {
  if (mismatches.empty()) return;
  std::string text;
  for (const ProvenanceMismatch& m : mismatches) text += (text.empty() ? "" : "\n  ") + session_json.string() + ": " + describe(m);
  if (!options.force) {
    throw JobFailure{kExitRefused, "refusing to replay: " + text +
                                       "\n  a replay repeats a session bit for bit only with the same build and files;"
                                       " --force replays anyway"};
  }
  for (const ProvenanceMismatch& m : mismatches) {
    result.warnings.push_back("--force: replaying although " + describe(m));
  }
}

// What a session's task came to: the outcome and its tick, and each finished step with its tick.
struct TaskStory {
  std::optional<std::string> outcome;
  std::optional<std::uint64_t> outcome_tick;
  std::vector<std::pair<std::string, std::uint64_t>> steps_done;
};

TaskStory story_of(const sim::SessionMeta& meta) {
  TaskStory story{meta.outcome, std::nullopt, {}};
  if (meta.completion) story.outcome_tick = meta.completion->tick;
  for (const sim::TaskDone& done : meta.tasks_done) story.steps_done.emplace_back(done.type, done.tick);
  return story;
}

// The replay's own story, from its session.json only: its events are the replay's business, not the check's.
TaskStory story_of(const std::filesystem::path& session_json) {
  std::ifstream in(session_json);
  const nlohmann::json doc = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) throw std::runtime_error(session_json.string() + ": the replay's session.json cannot be read");
  TaskStory story;
  if (doc.value("outcome", nlohmann::json()).is_string()) story.outcome = doc["outcome"].get<std::string>();
  const nlohmann::json completion = doc.value("completion", nlohmann::json());
  if (completion.is_object()) story.outcome_tick = completion.value("tick", std::uint64_t{0});
  for (const nlohmann::json& done : doc.value("tasks_done", nlohmann::json::array())) {
    story.steps_done.emplace_back(done.value("type", std::string()), done.value("tick", std::uint64_t{0}));
  }
  return story;
}

// The recorded outcome, its tick and the finished steps against the replay's.
std::optional<std::string> story_difference(const TaskStory& recorded, const TaskStory& replayed) {
  const auto outcome_text = [](const TaskStory& s) {
    if (!s.outcome) return std::string("no outcome");
    return "outcome " + *s.outcome + (s.outcome_tick ? " at tick " + std::to_string(*s.outcome_tick) : std::string());
  };
  if (recorded.outcome != replayed.outcome || recorded.outcome_tick != replayed.outcome_tick) {
    return "the outcome differs: recorded " + outcome_text(recorded) + ", replayed " + outcome_text(replayed);
  }
  const std::size_t steps = std::max(recorded.steps_done.size(), replayed.steps_done.size());
  for (std::size_t i = 0; i < steps; ++i) {
    const auto step_text = [i](const TaskStory& s) {
      if (i >= s.steps_done.size()) return std::string("not done");
      return s.steps_done[i].first + " done at tick " + std::to_string(s.steps_done[i].second);
    };
    if (step_text(recorded) != step_text(replayed)) {
      return "task step " + std::to_string(i + 1) + " differs: recorded " + step_text(recorded) + ", replayed " +
             step_text(replayed);
    }
  }
  return std::nullopt;
}

// What the video needs while the replay runs: the GL context, the painter and the encoder.
struct Film {
  std::unique_ptr<rfbsim::OffscreenGL> gl;  // declared first: the painter's context outlives it
  std::unique_ptr<sim::FramePainter> painter;
  std::unique_ptr<VideoWriter> writer;

  Film(const ReplayOptions& options, const sim::SessionMeta& meta) {
    if (meta.frame_width < 2 || meta.frame_height < 2) {
      throw JobFailure{kExitRefused, "session.json's frame is " + std::to_string(meta.frame_width) + "x" +
                                         std::to_string(meta.frame_height) + ": no size to render the video at"};
    }
    VideoSettings settings;
    settings.width = meta.frame_width;
    settings.height = meta.frame_height;
    settings.fps = meta.fps;
    writer = std::make_unique<VideoWriter>(*options.video, settings);  // first: a bad path fails before GL starts
    rfbsim::OffscreenGLOptions gl_options;
    gl_options.width = meta.frame_width;
    gl_options.height = meta.frame_height;
    gl = std::make_unique<rfbsim::OffscreenGL>(gl_options);
    painter = std::make_unique<sim::FramePainter>(*gl, video_style(options.view, meta));
  }
  ~Film() {
    painter.reset();  // its GL objects go while the context lives
    gl.reset();
  }
  Film(const Film&) = delete;
  Film& operator=(const Film&) = delete;
};

void run_job(const ReplayOptions& options, const ProgressFn& progress, ReplayResult& result) {
  // A watcher's folder (the video condition) has nothing of its own to replay: it only watched another session.
  if (const tools::SessionKind kind = tools::peek_session_kind(options.session_dir); kind.video) {
    throw JobFailure{kExitRefused, options.session_dir.string() + " is a watcher's session (condition video) of " +
                                       tools::watched_source(kind.yoked_to) + ": replay its source instead"};
  }
  // The log, read and checked (replay/recording.hpp: sim_rfb --replay opens recordings alike).
  sim::SessionLog log;
  try {
    log = read_recording(options.session_dir);
  } catch (const RecordingError& e) {
    throw JobFailure{kExitRefused, e.what()};
  }
  const sim::SessionMeta& meta = log.meta;
  const std::filesystem::path session_json = options.session_dir / "session.json";

  // The same build first (another one may not even read the scenario alike), then the same files.
  check_provenance(build_mismatches(meta, sim::rfbsim_version(), sim::rfbsim_build_id()), options, session_json, result);
  sim::PreparedSession prepared;
  try {
    prepared = rebuild_world(meta);
  } catch (const RecordingError& e) {
    throw JobFailure{kExitRefused, e.what()};
  }
  check_provenance(file_mismatches(meta, prepared.info), options, session_json, result);

  // Where the replay records, and the video's machinery.
  const OutputFolder out(options);
  std::optional<Film> film;
  if (options.video) film.emplace(options, meta);
  if (film) {
    result.renderer = film->gl->renderer();
    result.encoder = film->writer->encoder();
  }

  // The replay: each tick's inputs, then (when a frame is due) its picture, then the step.
  SessionReplay replay(log, std::move(prepared), out.path());
  result.end_tick = replay.end_tick();
  result.simulated_s = static_cast<double>(replay.end_tick()) / meta.tick_hz;
  std::uint64_t next_frame_tick = 0;  // frame k shows tick k * tick_hz / fps: its time in the video
  const auto start = Clock::now();
  while (!replay.done()) {
    replay.apply_inputs();
    if (film) {
      bool painted = false;
      while (next_frame_tick == replay.world().tick) {
        const auto t0 = Clock::now();
        if (!painted) film->painter->paint(replay.world(), replay.study().text(), /*always=*/true);
        painted = true;
        const rfbsim::FrameView picture = film->gl->read_frame();
        const auto t1 = Clock::now();
        film->writer->write(picture);
        const auto t2 = Clock::now();
        result.render_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        result.encode_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
        ++result.frames;
        next_frame_tick = static_cast<std::uint64_t>(result.frames) * static_cast<std::uint64_t>(meta.tick_hz) /
                          static_cast<std::uint64_t>(meta.fps);
      }
    }
    replay.step();
    if (progress && replay.world().tick % 60 == 0) progress(replay.world().time, result.simulated_s);
  }
  replay.finish();
  result.wall_s = std::chrono::duration<double>(Clock::now() - start).count();

  // The verdict: poses line by line, then the outcome and the finished steps.
  const TrajectoryComparison poses = compare_trajectories(options.session_dir / "trajectories.csv",
                                                          out.path() / "trajectories.csv", !meta.end_tick.has_value());
  result.rows = poses.rows;
  std::optional<std::string> difference;
  if (poses.difference) {
    difference = "the replay differs from the log at " + describe(*poses.difference);
  } else {
    difference = story_difference(story_of(meta), story_of(out.path() / "session.json"));
  }
  if (difference) {
    result.report.push_back(*difference);
    result.exit_status = kExitDiffers;
  } else {
    char summary[120];
    std::snprintf(summary, sizeof summary, "poses match the log: %zu rows, %.1f simulated seconds", poses.rows,
                  result.simulated_s);
    result.report.emplace_back(summary);
    result.report.push_back(meta.outcome ? "outcome matches: " + *meta.outcome + " at tick " +
                                               std::to_string(meta.completion ? meta.completion->tick : 0)
                                         : std::string("outcome matches: none, as recorded"));
    result.exit_status = kExitMatch;
  }
  if (!meta.end_tick) {
    result.warnings.push_back("the session did not end cleanly (no end_tick): replayed to its last trajectory tick " +
                              std::to_string(result.end_tick));
  }

  // The video is kept when it shows the recorded session (or when told to keep it anyway).
  if (film) {
    if (result.exit_status == kExitMatch || options.force) {
      film->writer->finish();
      result.video_bytes = film->writer->bytes();
      result.report.push_back("video: " + options.video->string() + ", " + std::to_string(result.frames) + " frames at " +
                              std::to_string(meta.fps) + " fps, " + std::to_string(meta.frame_width & ~1) + "x" +
                              std::to_string(meta.frame_height & ~1) + ", H.264 (" + result.encoder + "), " +
                              std::to_string((result.video_bytes + 500) / 1000) + " kB");
      if (result.exit_status != kExitMatch) result.warnings.push_back("--force: the video shows the replay, which departs from the log");
    } else {
      film->writer->discard();
      result.report.push_back("no video written: it would not show the recorded session (--force keeps it)");
    }
  }
  if (out.kept()) result.report.push_back("the replay's session data: " + out.path().string());
}

}  // namespace

sim::SceneStyle video_style(View view, const sim::SessionMeta& meta) {
  sim::SceneStyle style;
  style.top_view = view == View::Top;
  if (meta.frame_height > 0) {
    style.top_view_aspect = static_cast<float>(meta.frame_width) / static_cast<float>(meta.frame_height);
  }
  // The view the participant had, from the file rather than from the scenario as it reads today.
  style.camera = meta.camera;
  return style;
}

ReplayResult replay_session(const ReplayOptions& options, const ProgressFn& progress) {
  ReplayResult result;
  try {
    run_job(options, progress, result);
  } catch (const JobFailure& failure) {
    result.exit_status = failure.status;
    result.error = failure.message;
  } catch (const sim::SessionLogError& e) {
    result.exit_status = kExitRefused;
    result.error = e.what();
  } catch (const VideoError& e) {
    result.exit_status = kExitFailure;
    result.error = std::string("video: ") + e.what();
  } catch (const std::exception& e) {
    result.exit_status = kExitFailure;
    result.error = e.what();
  }
  return result;
}

}  // namespace rfbsim::replay
