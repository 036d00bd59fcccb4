// SPDX-License-Identifier: GPL-2.0-or-later
// A real sim_manager process for tests and benchmarks: started with a fresh data folder on a free port, with
// helpers to open links, read its session index, and watch its child processes and descriptors.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "eventually.hpp"
#include "http_client.hpp"
#include "sim_process.hpp"

namespace rfbsim::test {

/// The sim_manager binary under test (from the RFBSIM_SIM_MANAGER environment variable or the compiled-in
/// default, the one built here).
std::string sim_manager_path();

/// A fresh, empty folder under the system's temp dir, removed with everything in it on destruction.
class TempDir {
 public:
  /// `prefix` starts the folder's name; the process id, a counter and a random number follow.
  explicit TempDir(const std::string& prefix = "rfbsim-manager-test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// One row of the session index, as read with the reader's own SQL.
struct IndexRow {
  std::int64_t id = 0;
  std::string uid, token, scenario, params, seed, host_id, state, detail, exit_status, data_path;
  std::int64_t pid = 0;
  int port = 0;
  /// ISO 8601 UTC with milliseconds, e.g. "2025-01-31T12:00:00.123Z"; ready_at and ended_at are "" while unset.
  std::string created_at, ready_at, ended_at;
  /// When the first picture reached a participant ("" while the link is unspent), and why the data is
  /// incomplete ("" when it is complete).
  std::string spent_at, data_incomplete;
};

/// Small, cheap sessions for tests: the lab at 320x240, 15 frames per second.
std::vector<std::string> small_session_args();
/// `flags` followed by small_session_args().
std::vector<std::string> with_small_sessions(std::vector<std::string> flags);
/// `flags` followed by the flags that switch off the per-address abuse limits (rates on /start and upgrades,
/// unspent sessions per address), for tests that send many requests from loopback on purpose.
std::vector<std::string> without_abuse_limits(std::vector<std::string> flags);

/// How a ManagerUnderTest runs, beyond its data folder and flags.
struct ManagerOptions {
  std::string program = sim_manager_path();  ///< the sim_manager binary
  /// Sent on destruction if the manager still runs. SIGKILL leaves the sessions to PR_SET_PDEATHSIG;
  /// SIGTERM lets the manager end them itself, as a real shutdown does.
  int stop_signal = SIGKILL;
  std::chrono::milliseconds stop_timeout = std::chrono::seconds(5);  ///< wait for the exit on destruction
  std::chrono::milliseconds poll_interval = std::chrono::milliseconds(20);  ///< between looks in wait_for_*
  /// Where the manager's log (its stderr) is appended; empty = the test's own stderr.
  std::filesystem::path log_file;
};

class ManagerUnderTest {
 public:
  /// Starts sim_manager on 127.0.0.1 port 0 with `--data-dir data_dir` and `flags`; waits for its ready line.
  /// The caller owns `data_dir` and keeps it until this object is gone.
  ManagerUnderTest(const std::filesystem::path& data_dir, const std::vector<std::string>& flags,
                   ManagerOptions options = {});
  /// Stops the process with options.stop_signal unless it was stopped already.
  ~ManagerUnderTest();
  ManagerUnderTest(const ManagerUnderTest&) = delete;
  ManagerUnderTest& operator=(const ManagerUnderTest&) = delete;

  [[nodiscard]] int port() const { return process_->port(); }
  [[nodiscard]] pid_t pid() const { return process_->pid(); }
  SimProcess& process() { return *process_; }
  /// The participant WebSocket of session `token`: ws://127.0.0.1:<port>/s/<token>/ws (wss:// with `tls`).
  [[nodiscard]] std::string ws_url(const std::string& token, bool tls = false) const;
  /// The Origin a browser on the manager's own page sends: http://127.0.0.1:<port>.
  [[nodiscard]] std::string origin() const;

  /// GET /start?query (plain or TLS).
  net::HttpResponse start(const std::string& query, bool tls = false) const;
  /// GET of any target with optional extra headers.
  net::HttpResponse get(const std::string& target, const std::vector<std::pair<std::string, std::string>>& headers = {},
                        bool tls = false) const;
  /// POST /api/sessions/<id>/end with the admin token and the admin header.
  net::HttpResponse end_session(std::int64_t id, const std::string& admin_token) const;

  /// The session state reported by /s/<token>/status ("" if the request fails).
  std::string state_of(const std::string& token, bool tls = false) const;
  /// Polls /s/<token>/status and the index until both report `state`, or `timeout` passes.
  bool wait_for_state(const std::string& token, const std::string& state,
                      std::chrono::milliseconds timeout = std::chrono::seconds(20), bool tls = false) const;

  /// Every row of the index, oldest first (read with the caller's own SQLite connection).
  [[nodiscard]] std::vector<IndexRow> index_rows() const;
  /// The row of the session with `token`, if the index has one.
  [[nodiscard]] std::optional<IndexRow> row_for_token(const std::string& token) const;
  /// Polls the index until the row of `token` satisfies `done`; that row, or nullopt after `timeout`.
  [[nodiscard]] std::optional<IndexRow> wait_for_row(const std::string& token,
                                                     const std::function<bool(const IndexRow&)>& done,
                                                     std::chrono::milliseconds timeout) const;

  /// The manager's child processes now (from /proc).
  [[nodiscard]] std::vector<pid_t> children() const;
  /// How many descriptors the manager has open now.
  [[nodiscard]] int open_descriptors() const;
  /// A counter or gauge line's value from /metrics, e.g. metric("rfbsim_rejections_total{reason=\"busy\"}");
  /// -1 when absent.
  double metric(const std::string& name) const;

 private:
  /// The index's rows, all or only the one of `token`, oldest first.
  [[nodiscard]] std::vector<IndexRow> query_index(const std::optional<std::string>& token) const;

  std::filesystem::path data_dir_;
  ManagerOptions options_;
  std::unique_ptr<SimProcess> process_;
};

/// The token in a 302 to /s/<token>/ ("" when the response is not such a redirect).
std::string token_from_redirect(const net::HttpResponse& response);

/// The admin token the process tests give their managers (--admin-token).
inline constexpr const char* kAdminToken = "test-admin-token-0123456789";

/// POST `path` to `manager` with kAdminToken and, unless told not to, the admin API's X-Rfbsim-Admin header.
net::HttpResponse admin_post(const ManagerUnderTest& manager, const std::string& path, bool admin_header = true);

/// A loopback TCP port that was free a moment ago, for a program that must be told its port before it starts.
/// Drawn at random from 10000-19999: below the kernel's ephemeral ports, which every port-0 bind of the tests
/// running beside this one takes from, and below the cluster tests' 20000-31999, so that a port seen free is
/// rarely taken before the program binds it.
int free_loopback_port();

/// Whether a process with this id exists (zombies count as gone).
bool process_exists(pid_t pid);

/// Whether any process of group `pgid` still runs (zombies count as gone).
bool group_has_running_member(pid_t pgid);

/// TCP ports in LISTEN state on this machine (from /proc/net/tcp).
std::vector<int> listening_ports();

/// The process groups of the processes listening on TCP `port` now (from /proc/net/tcp and /proc/*/fd): a
/// port another test took meanwhile is told apart from one a session left behind.
std::vector<pid_t> listener_groups(int port);

}  // namespace rfbsim::test
