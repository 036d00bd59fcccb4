// SPDX-License-Identifier: GPL-2.0-or-later
// sim_report: session data to the study's tables and plots (docs/report.md). Parses the command line,
// runs the report job with a progress bar on stderr, and says what was skipped and written.
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

namespace {

int run(const rfbsim::report::CliOptions& options) {
  using namespace rfbsim::report;
  std::error_code ec;
  for (const std::filesystem::path& dir : options.data_dirs) {
    if (!std::filesystem::is_directory(dir, ec)) {
      std::fprintf(stderr, "sim_report: %s: no such folder\n", dir.c_str());
      return 2;
    }
  }

  const auto start = std::chrono::steady_clock::now();
  std::optional<ProgressBar> bar;
  const JobResult result = run_report(options.data_dirs, options.out_dir, [&](std::size_t done, std::size_t total) {
    if (!bar) bar.emplace(total, ::isatty(STDERR_FILENO) == 1);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fputs(bar->step(done, elapsed).c_str(), stderr);
  });
  if (bar) std::fputs(bar->finish().c_str(), stderr);

  for (const SkippedSession& s : result.skipped) {
    std::fprintf(stderr, "sim_report: skipped %s: %s\n", s.folder.c_str(), s.reason.c_str());
  }
  for (const std::string& w : result.warnings) std::fprintf(stderr, "sim_report: warning: %s\n", w.c_str());
  for (const RepeatedFolder& r : result.repeats) {
    std::fprintf(stderr, "sim_report: note: %s is %s again (%s); counted once\n", r.folder.c_str(), r.same_as.c_str(),
                 r.why.c_str());
  }
  for (const std::string& d : result.duplicate_uids) {
    std::fprintf(stderr, "sim_report: warning: duplicate uid: %s; flagged duplicate_uid\n", d.c_str());
  }
  for (const std::string& e : result.write_errors) std::fprintf(stderr, "sim_report: %s\n", e.c_str());
  if (result.sessions_found == 0) {
    std::string where;
    for (const std::filesystem::path& dir : options.data_dirs) where += (where.empty() ? "" : ", ") + dir.string();
    std::fprintf(stderr, "sim_report: no session folders (with a session.json) under %s\n", where.c_str());
  }
  std::fprintf(stderr, "sim_report: %zu sessions reported, %zu skipped\n", result.sessions_reported,
               result.skipped.size());
  if (result.sessions_excluded > 0) {
    std::fprintf(stderr, "sim_report: %zu of them without a participant (link never spent), left out of the "
                 "statistics\n", result.sessions_excluded);
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
  try {
    return run(*options);
  } catch (const std::exception& e) {
    // Nothing in the job should throw (sessions fail one by one); this is the last line of defence.
    std::fprintf(stderr, "sim_report: %s\n", e.what());
    return 1;
  }
}
