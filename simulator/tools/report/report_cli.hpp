// SPDX-License-Identifier: GPL-2.0-or-later
// sim_report's command line: `sim_report DATA_DIR [DATA_DIR...] [--out DIR] [--log-level L]`, `--help`. Pure:
// parsing only.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::report {

/// What the command line asks for.
struct CliOptions {
  bool help = false;              ///< --help / -h: print usage_text() and exit 0
  /// DATA_DIR...: hosts' data folders, the shared store or a merged copy, at least one, in the order given.
  std::vector<std::filesystem::path> data_dirs;
  std::filesystem::path out_dir;  ///< --out, else the first DATA_DIR's report/
  std::string log_level = "info";  ///< --log-level: error, warn, info or debug (rfbsim/log.hpp)
};

/// A command line that cannot be run (exit 2); the message says what is wrong.
struct CliError {
  std::string message;
};

/// Parses the arguments after the program's name. Returns the options, or sets `error` and returns none.
std::optional<CliOptions> parse_cli(const std::vector<std::string>& args, CliError& error);

/// The --help text.
std::string usage_text();

}  // namespace rfbsim::report
