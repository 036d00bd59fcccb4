// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's command line as a user meets it: --help, --print-config and its round trip, and a bad flag, through
// the real program.
#include <catch2/catch.hpp>
#include <sys/wait.h>

#include "manager_process.hpp"
#include "scratch_dir.hpp"
#include "sim_process.hpp"

using Catch::Contains;
using rfbsim::test::run_to_exit;
using rfbsim::test::ScratchDir;
using rfbsim::test::sim_manager_path;

TEST_CASE("sim_manager --help lists every flag and exits 0") {
  const auto help = run_to_exit(sim_manager_path(), {"--help"});
  CHECK(WIFEXITED(help.status));
  CHECK(WEXITSTATUS(help.status) == 0);
  CHECK_THAT(help.output, Contains("usage: sim_manager"));
  CHECK_THAT(help.output, Contains("--print-config") && Contains("--session-arg ARG") && Contains("--x11-xvnc PATH"));
  CHECK_THAT(help.output, Contains("(1..10000; default 4)"));
}

TEST_CASE("sim_manager --config PRINTED --print-config prints what made PRINTED") {
  ScratchDir dir;
  const std::string file = dir.write("manager.yaml", "port: 0\nmax_sessions: 3\nscenarios: [lab]\n"
                                                     "session_args: [--time-limit, \"60\"]\n"
                                                     "ros:\n  namespace: /study\n");
  const auto first = run_to_exit(sim_manager_path(), {"--config", file, "--link-secret", "0123456789abcdef",
                                                      "--frame-origins", "https://survey.example.org",
                                                      "--print-config"});
  REQUIRE(WEXITSTATUS(first.status) == 0);
  CHECK_THAT(first.output, Contains("\nmax_sessions: 3\n") && Contains("\nlink_secret: <set>\n") &&
                               Contains("\n  namespace: /study\n") && Contains("\n  - \"--time-limit\"\n  - 60\n"));
  CHECK_THAT(first.output, !Contains("0123456789abcdef"));
  const std::string printed = dir.write("printed.yaml", first.output);
  const auto second = run_to_exit(sim_manager_path(), {"--config", printed, "--print-config"});
  REQUIRE(WEXITSTATUS(second.status) == 0);
  CHECK(second.output == first.output);
  // Serving from it needs the secret itself.
  const auto serve = run_to_exit(sim_manager_path(), {"--config", printed});
  CHECK(WEXITSTATUS(serve.status) == 2);
  CHECK_THAT(serve.output, Contains("link_secret is <set>"));
}

TEST_CASE("sim_manager refuses a bad flag with exit code 2 and one line naming it") {
  const auto bad = run_to_exit(sim_manager_path(), {"--max-sessions", "0"});
  CHECK(WEXITSTATUS(bad.status) == 2);
  CHECK_THAT(bad.output, Contains("sim_manager: --max-sessions '0': expected an integer 1..10000"));
  const auto unknown = run_to_exit(sim_manager_path(), {"--max-session", "3"});
  CHECK(WEXITSTATUS(unknown.status) == 2);
  CHECK_THAT(unknown.output, Contains("sim_manager: unknown argument '--max-session'"));
}
