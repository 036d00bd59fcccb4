// SPDX-License-Identifier: GPL-2.0-or-later
// sim_report: session data to the study's tables and plots (docs/report.md). Parses the command line,
// runs the report job with a progress bar on stderr, and says what was skipped and written: through the log
// sink (rfbsim/log.hpp), progress and counts at info, what is doubtful at warn, what failed at error.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "progress_bar.hpp"
#include "report_cli.hpp"
#include "report_job.hpp"
#include "rfbsim/log.hpp"

namespace {

constexpr const char* kTag = "sim_report";

int run(const rfbsim::report::CliOptions& options) {
  using namespace rfbsim::report;
  std::error_code ec;
  for (const std::filesystem::path& dir : options.data_dirs) {
    if (!std::filesystem::is_directory(dir, ec)) {
      std::fprintf(stderr, "sim_report: %s: no such folder\n", dir.c_str());
      return 2;
    }
  }

  // Progress is info: a terminal's bar is redrawn in place, which no log line can do, so only its log form
  // goes through the sink.
  const auto start = std::chrono::steady_clock::now();
  const bool terminal = ::isatty(STDERR_FILENO) == 1;
  std::optional<ProgressBar> bar;
  ProgressFn progress;
  if (rfbsim::log::enabled(rfbsim::log::Level::kInfo)) {
    progress = [&](std::size_t done, std::size_t total) {
      if (!bar) bar.emplace(total, terminal);
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::string text = bar->step(done, elapsed);
      if (terminal) {
        std::fputs(text.c_str(), stderr);
      } else if (!text.empty()) {
        rfbsim::log::info(kTag, "%s", text.c_str());
      }
    };
  }
  const JobResult result = run_report(options.data_dirs, options.out_dir, progress);
  if (bar) std::fputs(bar->finish().c_str(), stderr);

  // A session that could not be read or a file not written makes the exit status 1: errors.
  for (const SkippedSession& s : result.skipped) {
    rfbsim::log::error(kTag, "skipped %s: %s", s.folder.c_str(), s.reason.c_str());
  }
  for (const std::string& w : result.warnings) rfbsim::log::warn(kTag, "warning: %s", w.c_str());
  for (const RepeatedFolder& r : result.repeats) {
    rfbsim::log::info(kTag, "note: %s is %s again (%s); counted once", r.folder.c_str(), r.same_as.c_str(),
                      r.why.c_str());
  }
  for (const std::string& d : result.duplicate_uids) {
    rfbsim::log::warn(kTag, "warning: duplicate uid: %s; flagged duplicate_uid", d.c_str());
  }
  for (const std::string& e : result.write_errors) rfbsim::log::error(kTag, "%s", e.c_str());
  if (result.sessions_found == 0) {
    std::string where;
    for (const std::filesystem::path& dir : options.data_dirs) where += (where.empty() ? "" : ", ") + dir.string();
    rfbsim::log::error(kTag, "no session folders (with a session.json) under %s", where.c_str());
  }
  rfbsim::log::info(kTag, "%zu sessions reported, %zu skipped", result.sessions_reported, result.skipped.size());
  if (result.sessions_excluded > 0) {
    rfbsim::log::info(kTag, "%zu of them without a participant (link never spent), left out of the statistics",
                      result.sessions_excluded);
  }
  if (result.video_sessions > 0) {
    rfbsim::log::info(kTag, "%zu video-condition pairs (%zu watchers' sessions, counted apart from the statistics)",
                      result.video_pairs, result.video_sessions);
  }
  for (const std::filesystem::path& file : result.written) std::printf("%s\n", file.c_str());
  return result.exit_status();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace rfbsim::report;
  const std::vector<std::string> args(argv + 1, argv + argc);
  CliError error;
  const std::optional<CliOptions> options = parse_cli(args, error);
  if (!options) {
    std::fprintf(stderr, "sim_report: %s\n(sim_report --help for usage)\n", error.message.c_str());
    return 2;
  }
  if (options->help) {
    std::fputs(usage_text().c_str(), stdout);
    return 0;
  }
  rfbsim::log::set_level(options->log_level);  // checked by the parser
  try {
    return run(*options);
  } catch (const std::exception& e) {
    // Nothing in the job should throw (sessions fail one by one); this is the last line of defence.
    std::fprintf(stderr, "sim_report: %s\n", e.what());
    return 1;
  }
}
