// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay: re-runs a recorded session from its log, checks the poses, and films it (docs/replay.md).
// Parses the command line, runs the replay with a progress line on stderr, and prints the verdict. What it says
// along the way goes through the log sink (rfbsim/log.hpp): the session found and the progress at info, the
// warnings at warn; the last line of a failed run is the program's own.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "progress_line.hpp"
#include "replay_cli.hpp"
#include "replay_job.hpp"
#include "rfbsim/log.hpp"
#include "session_lookup.hpp"

namespace {

constexpr const char* kTag = "sim_replay";

}  // namespace

int main(int argc, char** argv) {
  using namespace rfbsim::replay;
  const std::vector<std::string> args(argv + 1, argv + argc);
  CliError error;
  const std::optional<ReplayOptions> options = parse_cli(args, error);
  if (!options) {
    std::fprintf(stderr, "sim_replay: %s\n(sim_replay --help for usage)\n", error.message.c_str());
    return kExitRefused;
  }
  if (options->help) {
    std::fputs(usage_text().c_str(), stdout);
    return 0;
  }
  rfbsim::log::set_level(options->log_level);  // checked by the parser

  // --data-dir: find the one session the uid or id names across the hosts' folders.
  ReplayOptions chosen = *options;
  if (!chosen.data_dirs.empty()) {
    const LookupResult lookup = lookup_session(chosen.data_dirs, {chosen.uid, chosen.session, chosen.host});
    if (!lookup.found) {
      std::fprintf(stderr, "sim_replay: %s\n", lookup.error.c_str());
      return kExitRefused;
    }
    chosen.session_dir = lookup.found->dir;
    rfbsim::log::info(kTag, "session %s (host %s)", chosen.session_dir.c_str(), lookup.found->host.c_str());
  }

  // Progress is info: a terminal's line is redrawn in place, which no log line can do, so only its log form
  // goes through the sink.
  const auto start = std::chrono::steady_clock::now();
  const bool terminal = ::isatty(STDERR_FILENO) == 1;
  ProgressLine line(0.0, terminal);
  bool line_started = false;
  ProgressFn progress;
  if (!chosen.quiet && rfbsim::log::enabled(rfbsim::log::Level::kInfo)) {
    progress = [&](double done_s, double total_s) {
      if (!line_started) line = ProgressLine(total_s, terminal);
      line_started = true;
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::string text = line.step(done_s, elapsed);
      if (terminal) {
        std::fputs(text.c_str(), stderr);
      } else if (!text.empty()) {
        rfbsim::log::info(kTag, "%s", text.c_str());
      }
    };
  }
  const ReplayResult result = replay_session(chosen, progress);
  std::fputs(line.finish().c_str(), stderr);

  for (const std::string& warning : result.warnings) rfbsim::log::warn(kTag, "warning: %s", warning.c_str());
  if (!result.error.empty()) std::fprintf(stderr, "sim_replay: %s\n", result.error.c_str());
  for (const std::string& text : result.report) std::printf("%s\n", text.c_str());
  return result.exit_status;
}
