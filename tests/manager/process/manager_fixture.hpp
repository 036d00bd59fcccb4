// SPDX-License-Identifier: GPL-2.0-or-later
// A real sim_manager process for tests: started with a fresh data folder on a free port, with helpers to
// open links, read its session index, and watch its child processes and descriptors.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "http_client.hpp"
#include "sim_process.hpp"

namespace rfbsim::test {

/// The sim_manager binary under test.
std::string sim_manager_path();

/// A fresh, empty folder under the system's temp dir, removed with everything in it on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// One row of the session index, as the test reads it with its own SQL.
struct IndexRow {
  std::int64_t id = 0;
  std::string uid, token, scenario, params, seed, host_id, state, detail, exit_status, data_path;
  std::int64_t pid = 0;
  int port = 0;
  bool ready_at_set = false;
  bool ended_at_set = false;
};

/// Small, cheap sessions for tests: the lab at 320x240, 15 frames per second.
std::vector<std::string> small_session_args();

class ManagerUnderTest {
 public:
  /// Starts sim_manager on 127.0.0.1 port 0 with `--data-dir data_dir` and `flags`; waits for its ready line.
  ManagerUnderTest(const std::filesystem::path& data_dir, const std::vector<std::string>& flags);

  [[nodiscard]] int port() const { return process_->port(); }
  [[nodiscard]] pid_t pid() const { return process_->pid(); }
  SimProcess& process() { return *process_; }

  /// GET /start?query (plain or TLS).
  net::HttpResponse start(const std::string& query, bool tls = false);
  /// GET of any target with optional extra headers.
  net::HttpResponse get(const std::string& target, const std::vector<std::pair<std::string, std::string>>& headers = {},
                        bool tls = false);
  /// POST /api/sessions/<id>/end with the admin token and the admin header.
  net::HttpResponse end_session(std::int64_t id, const std::string& admin_token);

  /// The session state reported by /s/<token>/status ("" if the request fails).
  std::string state_of(const std::string& token, bool tls = false);
  /// Polls /s/<token>/status until it reports `state` or `timeout` passes.
  bool wait_for_state(const std::string& token, const std::string& state,
                      std::chrono::milliseconds timeout = std::chrono::seconds(20), bool tls = false);

  /// Every row of the index, oldest first (read with the test's own SQLite connection).
  [[nodiscard]] std::vector<IndexRow> index_rows() const;
  [[nodiscard]] std::optional<IndexRow> row_for_token(const std::string& token) const;

  /// The manager's child processes now (from /proc).
  [[nodiscard]] std::vector<pid_t> children() const;
  /// How many descriptors the manager has open now.
  [[nodiscard]] int open_descriptors() const;
  /// A counter or gauge line's value from /metrics, e.g. metric("rfbsim_rejections_total{reason=\"busy\"}").
  double metric(const std::string& name);

 private:
  std::filesystem::path data_dir_;
  std::unique_ptr<SimProcess> process_;
};

/// The token in a 302 to /s/<token>/ ("" when the response is not such a redirect).
std::string token_from_redirect(const net::HttpResponse& response);

/// Whether a process with this id exists (zombies count as gone).
bool process_exists(pid_t pid);

/// Whether any process of group `pgid` still runs (zombies count as gone).
bool group_has_running_member(pid_t pgid);

/// TCP ports in LISTEN state on this machine (from /proc/net/tcp).
std::vector<int> listening_ports();

/// Waits until `done()` holds, checking every 20 ms; false after `timeout`.
bool eventually(const std::function<bool()>& done, std::chrono::milliseconds timeout);

}  // namespace rfbsim::test
