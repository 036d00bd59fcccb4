// SPDX-License-Identifier: GPL-2.0-or-later
// A real study cluster for tests: scripts/run-cluster-demo.sh run as a child process (N sim_manager hosts and
// HAProxy in front on loopback), with helpers that speak to it as participants and operators do: through
// HAProxy's one port, by /start links, session paths and the admin API; and faults an operator meets: a host
// killed, restarted, drained, and HAProxy reloaded.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "http_client.hpp"

namespace rfbsim::test {

/// How a cluster is started.
struct ClusterOptions {
  int hosts = 3;         ///< --hosts
  int max_sessions = 1;  ///< --max-sessions per host
  bool rate_limit = false;  ///< --rate-limit: keep the managers' per-address limits
  /// The base manager config (YAML text) every host gets with --config; "" passes none.
  std::string config_yaml;
};

/// One host as the script printed it.
struct ClusterHost {
  std::string id;  ///< h1, h2, ...
  pid_t pid = 0;   ///< the manager's process id (updated by restart_host)
  int port = 0;    ///< the manager's own port (HAProxy reaches it there)
  std::filesystem::path data;  ///< its data dir
};

/// Where a /start ended after following the cluster's own 303s.
struct StartResult {
  net::HttpResponse response;     ///< the last answer (302 to the session, 409, 503...)
  std::vector<int> statuses;      ///< every answer's status in order, e.g. {303, 302}
  std::string first_host;         ///< the pool's pick (HAProxy's X-Rfbsim-Host on the first answer)
  std::string host;               ///< the host of the session path in a final 302 ("" otherwise)
  std::string token;              ///< the session token in a final 302 ("" otherwise)
};

/// Base configs for sessions of the two kinds the suite uses.
/// examples/minimal (session_kind rfb): cheap, animated, no data; a session no browser opened (or left) lasts
/// `unseen_s` seconds.
std::string minimal_sessions_yaml(int unseen_s = 120);
std::string sim_rfb_sessions_yaml();  ///< sim_rfb in the lab at 320x240, 15 fps: records a session's data

class ClusterUnderTest {
 public:
  /// Picks free ports, runs the script with a fresh run dir and waits (up to 90 s) for `cluster ready`.
  /// Throws std::runtime_error, with the script's output, when it does not get there.
  explicit ClusterUnderTest(const ClusterOptions& options);
  /// Stops the script with SIGTERM (it stops every process it started) and waits; kills what is left. Removes
  /// the run dir unless RFBSIM_KEEP_CLUSTER is set.
  ~ClusterUnderTest();
  ClusterUnderTest(const ClusterUnderTest&) = delete;
  ClusterUnderTest& operator=(const ClusterUnderTest&) = delete;

  /// Stops the cluster now (as the destructor does); the run dir and the hosts' data stay until destruction.
  void stop();

  [[nodiscard]] int port() const { return port_; }  ///< HAProxy's public port
  [[nodiscard]] const std::vector<ClusterHost>& hosts() const { return hosts_; }
  [[nodiscard]] const ClusterHost& host(const std::string& id) const;
  [[nodiscard]] const std::filesystem::path& run_dir() const { return run_dir_; }
  [[nodiscard]] const std::string& admin_token() const { return admin_token_; }

  /// GET through HAProxy.
  net::HttpResponse get(const std::string& target,
                        const std::vector<std::pair<std::string, std::string>>& headers = {}) const;
  /// GET straight to host `id`'s own port (no balancer).
  net::HttpResponse get_direct(const std::string& id, const std::string& target) const;
  /// GET /start?`query` through HAProxy, following up to 3 of the cluster's redirects to /<host>/start.
  /// `path` may name a host's own /<host>/start; `via_port` another way in to HAProxy (a SourceForwarder's
  /// port; 0 = HAProxy's port).
  StartResult start(const std::string& query, const std::string& path = "/start", int via_port = 0) const;
  /// The session's state as /<host>/s/<token>/status says through HAProxy ("" when it answers no JSON state).
  std::string state_of(const std::string& host, const std::string& token) const;
  /// An admin API POST through HAProxy to host `id`, e.g. admin_post("h2", "/api/drain").
  net::HttpResponse admin_post(const std::string& id, const std::string& path) const;
  /// Ends the session with `token` on host `id` through the admin API; false if it was not found.
  bool end_session(const std::string& id, const std::string& token) const;

  /// HAProxy's status of `server` in `backend` from its stats CSV ("UP", "DOWN", "DRAIN", "MAINT", "UP 1/2"...;
  /// "" when not found).
  std::string server_status(const std::string& backend, const std::string& server) const;
  /// Polls server_status until it starts with `prefix`; false after `timeout`.
  bool wait_server_status(const std::string& backend, const std::string& server, const std::string& prefix,
                          std::chrono::milliseconds timeout) const;

  /// Sends `signal` to host `id`'s manager and reaps it if it is this object's child.
  void signal_host(const std::string& id, int signal);
  /// Starts host `id` again with the argv the script used (its hN.argv), records its pid where the script
  /// looks (hN.pid) and waits until it answers /healthz on its port. Throws when it does not come up.
  void restart_host(const std::string& id);
  /// SIGUSR2 to HAProxy's master: a reload from the same config (new workers, the old ones finish); waits
  /// until the master logs the new worker's "Loading success.", and throws when it does not.
  void reload_haproxy();

 private:
  /// One try at starting the cluster on a fresh base port; throws ScriptExitedEarly when the script gave up
  /// before it was ready (a port seen free was taken meanwhile), anything else on other failures.
  void launch(const ClusterOptions& options);

  int port_ = 0;
  int stats_port_ = 0;
  pid_t script_pid_ = -1;
  pid_t haproxy_pid_ = -1;
  int output_fd_ = -1;
  std::filesystem::path run_dir_;
  std::string admin_token_;
  std::vector<ClusterHost> hosts_;
  std::vector<pid_t> own_children_;  // hosts restarted here
  bool owns_run_dir_ = true;
};

/// A free base port P for a cluster of `hosts`: nothing listens on P..P+hosts, P+101.., P+201.., P+300.
int free_cluster_base_port(int hosts);

/// The host and token of a /<host>/s/<token>/ Location ("", "" when it is not one).
std::pair<std::string, std::string> session_of_location(const std::string& location);

}  // namespace rfbsim::test
