// SPDX-License-Identifier: GPL-2.0-or-later
// sim_report's command line: each option declared once with CLI11, from which parsing and --help follow.
#include "report_cli.hpp"

#include "cli/command_line.hpp"

namespace rfbsim::report {

namespace {

// Declares sim_report's arguments on `app`: the options into `options`, the data folders into `dirs`.
void declare_report_cli(CLI::App& app, CliOptions& options, std::vector<std::string>& dirs) {
  cli::configure(app);
  app.description(
      "Reads every session folder under each DATA_DIR (each folder holding a session.json, e.g.\n"
      "DATA_DIR/sessions/<id>-<uid>/ as sim_manager lays them out, or <store>/<host_id>/<folder>/ in the\n"
      "study's shared store) and writes the study's tables and plots:\n"
      "  sessions.csv   one row per session (docs/report.md defines every column)\n"
      "  summary.csv    rates, means and medians for all sessions and per scenario\n"
      "  report.md      the tables in Markdown\n"
      "  report.html    the tables, Hall-zone histograms and a trajectory plot per session (self-contained)");
  app.footer(
      "A session that cannot be read is skipped and named on stderr with the reason; the others are reported.\n"
      "Where sim_manager left a manager.json beside a session, its state and whether its link was spent are\n"
      "reported, and a session nobody saw (abandoned) is left out of the statistics and counted.\n"
      "Several hosts: each session's host is manager.json's host, else the store folder it is in (else its\n"
      "DATA_DIR). A session found twice (a host's folder and the store's copy) is reported once; a uid with\n"
      "sessions on two hosts is a warning, and its sessions are flagged (duplicate_uid) but still reported.\n"
      "Exit status: 0 all reported, 1 data errors (sessions skipped, none found, or output not written),\n"
      "2 usage errors.");
  app.add_flag("-h,--help", options.help, "print this help and exit");
  app.add_option("DATA_DIR", dirs, "hosts' data folders, the shared store or a merged copy (one or more)")
      ->type_name("DIR");
  app.add_option("--out", options.out_dir,
                 "where to write them (default: the first DATA_DIR's report/; created if needed)")
      ->type_name("DIR")->check(cli::non_empty());
  cli::add_log_level(app, options.log_level);
}

}  // namespace

std::optional<CliOptions> parse_cli(const std::vector<std::string>& args, CliError& error) {
  CliOptions options;
  std::vector<std::string> dirs;
  CLI::App app("", "sim_report");
  declare_report_cli(app, options, dirs);
  error.message = cli::parse(app, args);
  if (!error.message.empty()) return std::nullopt;
  if (options.help) return options;
  if (dirs.empty()) {
    error.message = "DATA_DIR is missing";
    return std::nullopt;
  }
  for (const std::string& dir : dirs) {
    if (dir.empty()) {
      error.message = "a DATA_DIR is empty";
      return std::nullopt;
    }
    options.data_dirs.emplace_back(dir);
  }
  if (options.out_dir.empty()) options.out_dir = options.data_dirs.front() / "report";
  return options;
}

std::string usage_text() {
  CliOptions options;
  std::vector<std::string> dirs;
  CLI::App app("", "sim_report");
  declare_report_cli(app, options, dirs);
  return app.help();
}

}  // namespace rfbsim::report
