// SPDX-License-Identifier: GPL-2.0-or-later
// The real sim_report binary (SIM_REPORT_BINARY, set by tests/report/CMakeLists.txt) run from a test.
#pragma once

#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "session_files.hpp"

namespace rfbsim::report::test {

/// Runs sim_report with `args` (already quoted), stdout and stderr to stdout.txt and stderr.txt in
/// `scratch`; returns its exit status.
inline int sim_report(const ScratchDir& scratch, const std::string& args) {
  const std::string command = std::string("'") + SIM_REPORT_BINARY + "' " + args + " >'" +
                              (scratch.path() / "stdout.txt").string() + "' 2>'" +
                              (scratch.path() / "stderr.txt").string() + "'";
  const int status = std::system(command.c_str());
  REQUIRE(WIFEXITED(status));
  return WEXITSTATUS(status);
}

/// A path in single quotes, for sim_report's command line (test paths hold no quote).
inline std::string quoted(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

}  // namespace rfbsim::report::test
