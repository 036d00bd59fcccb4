// SPDX-License-Identifier: GPL-2.0-or-later
// sim_report's command line.
#include "report_cli.hpp"

#include "cli_option.hpp"

namespace rfbsim::report {

std::optional<CliOptions> parse_cli(const std::vector<std::string>& args, CliError& error) {
  CliOptions options;
  std::vector<std::string> positional;
  bool out_given = false;
  bool options_end = false;  // after "--" everything is a path, even "-x"
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (options_end || arg.empty() || arg[0] != '-' || arg == "-") {
      positional.push_back(arg);
    } else if (arg == "--") {
      options_end = true;
    } else if (arg == "--help" || arg == "-h") {
      options.help = true;
      return options;
    } else if (tools::is_option(arg, "--out")) {
      const auto value = tools::option_value(args, i, "--out", "a folder", error.message);
      if (!value) return std::nullopt;
      options.out_dir = *value;
      out_given = true;
    } else {
      error.message = "unknown option '" + arg + "'";
      return std::nullopt;
    }
  }
  if (positional.empty()) {
    error.message = "DATA_DIR is missing";
    return std::nullopt;
  }
  for (const std::string& dir : positional) {
    if (dir.empty()) {
      error.message = "a DATA_DIR is empty";
      return std::nullopt;
    }
    options.data_dirs.emplace_back(dir);
  }
  if (!out_given) options.out_dir = options.data_dirs.front() / "report";
  return options;
}

std::string usage_text() {
  return "Usage: sim_report DATA_DIR [DATA_DIR...] [--out DIR]\n"
         "\n"
         "Reads every session folder under each DATA_DIR (each folder holding a session.json, e.g.\n"
         "DATA_DIR/sessions/<id>-<uid>/ as sim_manager lays them out, or <store>/<host_id>/<folder>/ in the\n"
         "study's shared store) and writes the study's tables and plots:\n"
         "  sessions.csv   one row per session (docs/report.md defines every column)\n"
         "  summary.csv    rates, means and medians for all sessions and per scenario\n"
         "  report.md      the tables in Markdown\n"
         "  report.html    the tables, Hall-zone histograms and a trajectory plot per session (self-contained)\n"
         "\n"
         "Options:\n"
         "  --out DIR   where to write them (default: the first DATA_DIR's report/; created if needed)\n"
         "  -h, --help  this text\n"
         "\n"
         "A session that cannot be read is skipped and named on stderr with the reason; the others are reported.\n"
         "Where sim_manager left a manager.json beside a session, its state and whether its link was spent are\n"
         "reported, and a session nobody saw (abandoned) is left out of the statistics and counted.\n"
         "Several hosts: each session's host is manager.json's host, else the store folder it is in (else its\n"
         "DATA_DIR). A session found twice (a host's folder and the store's copy) is reported once; a uid with\n"
         "sessions on two hosts is a warning, and its sessions are flagged (duplicate_uid) but still reported.\n"
         "Exit status: 0 all reported, 1 data errors (sessions skipped, none found, or output not written),\n"
         "2 usage errors.\n";
}

}  // namespace rfbsim::report
