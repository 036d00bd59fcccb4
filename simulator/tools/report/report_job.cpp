// SPDX-License-Identifier: GPL-2.0-or-later
// The report job: read, measure, plot, render, write.
#include "report_job.hpp"

#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>

#include "duplicate_uids.hpp"
#include "manager_record.hpp"
#include "record/digest.hpp"
#include "participation.hpp"
#include "record/session_log.hpp"
#include "report_csv.hpp"
#include "report_html.hpp"
#include "report_markdown.hpp"
#include "scenario/scenario.hpp"
#include "session_catalog.hpp"
#include "session_samples.hpp"
#include "trajectory_plot.hpp"
#include "video_pairs.hpp"
#include "watcher_session.hpp"

namespace rfbsim::report {

namespace {

// The map of one scenario file, loaded once for all its sessions.
struct LoadedMap {
  std::optional<MapDrawing> drawing;  // none when the file could not be loaded
  std::string problem;                // why not
  std::string sha256;                 // of the file as it is now ("" if unreadable)
};

class MapCache {
 public:
  const LoadedMap& get(const std::string& scenario_file) {
    auto it = maps_.find(scenario_file);
    if (it != maps_.end()) return it->second;
    LoadedMap map;
    if (scenario_file.empty()) {
      map.problem = "the session ran in the built-in test room (no scenario file)";
    } else {
      try {
        const sim::Scenario scenario = sim::load_scenario(scenario_file);
        map.drawing = draw_map(scenario.map, scenario.props, "map-" + std::to_string(definitions_.size()));
        definitions_.push_back(map.drawing->definition);
        map.sha256 = sim::sha256_file(scenario_file);
      } catch (const std::exception& e) {
        map.problem = e.what();
      }
    }
    return maps_.emplace(scenario_file, std::move(map)).first->second;
  }
  std::vector<std::string> take_definitions() { return std::move(definitions_); }

 private:
  std::map<std::string, LoadedMap> maps_;
  std::vector<std::string> definitions_;
};

std::string caption(const sim::SessionLog& log, const SampledSession& samples, const LoadedMap& map) {
  std::string out = std::to_string(samples.samples.size()) + " samples at " + std::to_string(log.meta.trajectory_hz) +
                    " Hz";
  if (samples.partial_samples > 0) out += " (" + std::to_string(samples.partial_samples) + " partial left out)";
  out += ". ";
  if (!map.drawing) {
    out += "Drawn without walls: the scenario file could not be loaded (" + map.problem + ").";
  } else {
    out += "Walls and props from " + log.meta.scenario_file + ".";
    if (!log.meta.scenario_sha256.empty() && map.sha256 != log.meta.scenario_sha256) {
      out += " That file has changed since this session ran (its SHA-256 differs from session.json's): the "
             "walls may not be the ones the participant saw.";
    }
  }
  return out;
}

// A session's folder as the report names it: relative to the data folder when there is one (as before
// several were taken), else as found, which tells the data folders apart.
std::string folder_name(const tools::FoundSession& found, std::size_t data_dirs) {
  if (data_dirs > 1) return found.dir.string();
  return found.relative.string();
}

// manager.json into `metrics`, when the folder has one. A broken one, or one of another participant (a folder
// pieced together by hand), is a warning: the session is then reported as if run without the manager.
void add_record(const std::filesystem::path& dir, SessionMetrics& metrics, std::vector<std::string>& warnings) {
  try {
    const std::optional<ManagerRecord> record = read_manager_record(dir);
    if (!record) return;
    const std::string file = (dir / "manager.json").string();
    if (record->uid != metrics.uid) {
      warnings.push_back(file + ": uid '" + record->uid + "' is not session.json's '" + metrics.uid + "'; ignored");
      return;
    }
    // session.json is sim_rfb's account of what the session was; the manager's differing is worth a look.
    const std::string condition = metrics.video() ? "video" : "interactive";
    if (record->condition != condition) {
      warnings.push_back(file + ": condition '" + record->condition + "', but session.json is a" +
                         (metrics.video() ? " watcher's (video)" : "n interactive session's") +
                         "; reported as session.json says");
    }
    if (metrics.watcher && metrics.watcher->yoked_to && record->yoked_to &&
        *metrics.watcher->yoked_to != *record->yoked_to) {
      warnings.push_back(file + ": yoked_to " + std::to_string(*record->yoked_to) + ", but session.json's is " +
                         std::to_string(*metrics.watcher->yoked_to) + "; paired as session.json says");
    }
    add_manager_record(*record, metrics);
  } catch (const ManagerRecordError& e) {
    warnings.push_back(std::string(e.what()) + "; reported without it");
  } catch (const std::exception& e) {
    warnings.push_back((dir / "manager.json").string() + ": " + e.what() + "; reported without it");
  }
}

// The session id a sim_manager folder's name gives ("12-p007": 12); none for any other name.
std::optional<std::int64_t> id_from_folder_name(const std::filesystem::path& dir) {
  const std::string name = dir.lexically_normal().filename().string();
  const std::size_t dash = name.find('-');
  if (dash == 0 || dash == std::string::npos || dash > 18) return std::nullopt;
  if (name.find_first_not_of("0123456789") != dash) return std::nullopt;
  return std::stoll(name.substr(0, dash));
}

// One session folder measured (an interactive session) or described (a watcher's), with its plot.
std::pair<SessionMetrics, SessionPlot> report_session(const std::filesystem::path& dir, MapCache& maps) {
  const tools::SessionKind kind = tools::peek_session_kind(dir);
  if (!kind.unknown_condition.empty()) {
    throw std::runtime_error((dir / "session.json").string() + ": key 'condition': '" + kind.unknown_condition +
                             "' is neither interactive nor video");
  }
  // A watcher's folder holds its session.json alone: nothing was walked, so there is nothing to plot.
  if (kind.video) return {watcher_metrics(tools::read_watcher_session(dir)), SessionPlot{}};
  const sim::SessionLog log = sim::read_session(dir);
  const SampledSession samples = assemble_samples(log);
  SessionMetrics metrics = session_metrics(log, samples);
  const LoadedMap& map = maps.get(log.meta.scenario_file);
  SessionPlot plot{trajectory_svg(samples, map.drawing ? &*map.drawing : nullptr), caption(log, samples, map)};
  return {std::move(metrics), std::move(plot)};
}

// Writes a whole file through a temporary and a rename, so that a reader never sees half a report.
void write_file(const std::filesystem::path& path, const std::string& text, JobResult& result) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      result.write_errors.push_back(path.string() + ": cannot write");
      return;
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    result.write_errors.push_back(path.string() + ": cannot write (" + ec.message() + ")");
    return;
  }
  result.written.push_back(path);
}

}  // namespace

int JobResult::exit_status() const {
  return sessions_found > 0 && skipped.empty() && write_errors.empty() ? 0 : 1;
}

JobResult run_report(const std::filesystem::path& data_dir, const std::filesystem::path& out_dir,
                     const ProgressFn& progress) {
  return run_report(std::vector<std::filesystem::path>{data_dir}, out_dir, progress);
}

JobResult run_report(const std::vector<std::filesystem::path>& data_dirs, const std::filesystem::path& out_dir,
                     const ProgressFn& progress) {
  JobResult result;
  ReportData data;
  for (const std::filesystem::path& dir : data_dirs) data.data_dirs.push_back(dir.string());
  MapCache maps;

  // Each session on its own: whatever goes wrong with one is its reason for being skipped.
  const tools::SessionCatalog catalog = tools::catalog_sessions(data_dirs);
  const std::vector<tools::FoundSession>& found = catalog.sessions;
  result.sessions_found = found.size();
  for (std::size_t i = 0; i < found.size(); ++i) {
    const std::string folder = folder_name(found[i], data_dirs.size());
    try {
      auto [metrics, plot] = report_session(found[i].dir, maps);
      metrics.folder = folder;
      metrics.host = found[i].host;
      metrics.session_id = id_from_folder_name(found[i].dir);
      add_record(found[i].dir, metrics, data.warnings);
      data.sessions.push_back(std::move(metrics));
      data.plots.push_back(std::move(plot));
    } catch (const sim::SessionLogError& e) {
      data.skipped.push_back({folder, e.what()});
    } catch (const tools::WatcherSessionError& e) {
      data.skipped.push_back({folder, e.what()});
    } catch (const std::exception& e) {
      data.skipped.push_back({folder, std::string("cannot be reported: ") + e.what()});
    }
    if (progress) progress(i + 1, found.size());
  }
  // Copies of a reported session (a host's folder and the store's both given) count once; a uid on two
  // hosts is flagged, not dropped: the analysis decides.
  for (const tools::RepeatedSession& r : catalog.repeats) {
    data.repeats.push_back({r.dir.string(), folder_name(found[r.kept], data_dirs.size()), r.why});
  }
  // Each watcher with the session it watched; one without is a warning that names both.
  data.video = pair_watchers(data.sessions);
  for (const std::string& w : data.video.warnings) data.warnings.push_back(w);
  result.video_sessions = data.video.watchers;
  result.video_pairs = data.video.pairs.size();
  data.duplicates = flag_duplicate_uids(data.sessions);
  for (const DuplicateUid& d : data.duplicates) result.duplicate_uids.push_back(duplicate_uid_line(d, data.sessions));
  result.repeats = data.repeats;
  result.sessions_reported = data.sessions.size();
  result.skipped = data.skipped;
  result.warnings = data.warnings;
  data.groups = summarize(data.sessions);
  data.exclusions = exclusions(data.sessions);
  result.sessions_excluded = data.groups.front().excluded;
  data.map_definitions = maps.take_definitions();

  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    result.write_errors.push_back(out_dir.string() + ": cannot create the folder (" + ec.message() + ")");
    return result;
  }
  write_file(out_dir / "sessions.csv", sessions_csv(data.sessions), result);
  write_file(out_dir / "summary.csv", summary_csv(data.groups), result);
  write_file(out_dir / "pairs.csv", pairs_csv(data.sessions, data.video.pairs), result);
  write_file(out_dir / "report.md", markdown_report(data), result);
  write_file(out_dir / "report.html", html_report(data), result);
  return result;
}

}  // namespace rfbsim::report
