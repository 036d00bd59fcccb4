// SPDX-License-Identifier: GPL-2.0-or-later
// Starting the measured sim_manager and its sessions; see manager_session.hpp.
#include "manager_session.hpp"

#include <csignal>
#include <stdexcept>

#include "bench_util.hpp"

namespace rfbsim::bench {

test::ManagerUnderTest start_manager(const ManagerRun& run, const std::filesystem::path& data_dir,
                                     const std::vector<std::string>& session_args, int max_sessions,
                                     const std::vector<std::string>& extra_flags) {
  std::vector<std::string> flags = {"--max-sessions", std::to_string(max_sessions), "--admin-token", kBenchAdminToken,
                                    "--scenarios", run.scenario, "--max-duration-s", "3600"};
  flags.insert(flags.end(), extra_flags.begin(), extra_flags.end());
  for (const std::string& arg : session_args) flags.insert(flags.end(), {"--session-arg", arg});
  test::ManagerOptions how;
  how.program = run.program;
  how.stop_signal = SIGTERM;
  how.stop_timeout = std::chrono::milliseconds(30000);
  // Link to first frame times "admin end -> session gone" by polling the index.
  how.poll_interval = std::chrono::milliseconds(5);
  const StderrToFile redirect(run.log);
  return test::ManagerUnderTest(data_dir, flags, how);
}

std::string start_session(const test::ManagerUnderTest& manager, const std::string& uid, const std::string& scenario) {
  const test::net::HttpResponse response = manager.start("uid=" + uid + "&scenario=" + scenario);
  const std::string token = test::token_from_redirect(response);
  if (token.empty()) {
    throw std::runtime_error("/start for uid " + uid + " answered " + std::to_string(response.status) + ": " +
                             response.body.substr(0, 200));
  }
  return token;
}

void end_session(const test::ManagerUnderTest& manager, std::int64_t id) {
  const test::net::HttpResponse response = manager.end_session(id, kBenchAdminToken);
  if (response.status != 200) {
    throw std::runtime_error("ending session " + std::to_string(id) + " answered " + std::to_string(response.status) +
                             ": " + response.body);
  }
}

test::IndexRow wait_for_row(const test::ManagerUnderTest& manager, const std::string& token,
                            const std::function<bool(const test::IndexRow&)>& done,
                            std::chrono::milliseconds timeout, const char* what) {
  if (auto row = manager.wait_for_row(token, done, timeout)) return *row;
  const auto last = manager.row_for_token(token);
  throw std::runtime_error(std::string("session ") + token + " never " + what + " (state " +
                           (last ? last->state : "absent") + ")");
}

bool is_live_state(const std::string& state) { return state == "starting" || state == "running" || state == "ending"; }

}  // namespace rfbsim::bench
