// SPDX-License-Identifier: GPL-2.0-or-later
// bench_cluster (a): the call loop, the fault schedule, and the checks after each fault and at the end.
#include "cluster_targets.hpp"

#include <signal.h>
#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "manager_process.hpp"

namespace rfbsim::bench {

namespace {

using test::ClusterUnderTest;

struct HostState {
  bool killed = false;
  bool drained = false;
};

// A host's own /healthz: whether it can take a new session now (answers 200, fewer live than capacity).
bool has_free_slot(const ClusterUnderTest& cluster, const std::string& host) {
  const auto response = cluster.get_direct(host, "/healthz");
  if (response.status != 200) return false;
  const auto json = nlohmann::json::parse(response.body, nullptr, false);
  if (json.is_discarded() || !json.contains("live_sessions") || !json.contains("capacity")) return false;
  return json["live_sessions"].get<int>() < json["capacity"].get<int>();
}

// uid -> the hosts whose own index has a session of it.
std::map<std::string, std::set<std::string>> homes_in_indexes(const ClusterUnderTest& cluster) {
  std::map<std::string, std::set<std::string>> homes;
  for (const auto& host : cluster.hosts()) {
    sqlite3* db = nullptr;
    const std::string file = (host.data / "sessions.db").string();
    if (sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      sqlite3_close(db);
      throw std::runtime_error("cannot open " + file);
    }
    sqlite3_busy_timeout(db, 5000);
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db, "SELECT uid FROM sessions", -1, &statement, nullptr) == SQLITE_OK) {
      while (sqlite3_step(statement) == SQLITE_ROW) {
        homes[reinterpret_cast<const char*>(sqlite3_column_text(statement, 0))].insert(host.id);
      }
    }
    sqlite3_finalize(statement);
    sqlite3_close(db);
  }
  return homes;
}

bool is_live_state(const std::string& state) { return state == "starting" || state == "running" || state == "ending"; }

}  // namespace

TargetResult run_targets(ClusterUnderTest& cluster, const TargetOptions& options) {
  TargetResult result;
  std::mt19937 random(options.seed);
  std::map<std::string, HostState> hosts;
  for (const auto& host : cluster.hosts()) hosts[host.id] = {};
  std::map<std::string, std::string> home;    // uid -> the host of its first session (the registry's record)
  std::map<std::string, std::string> live;    // uid -> token of the session the bench believes live
  std::set<std::string> tokens_seen;
  const auto up = [&](const std::string& id) { return !hosts[id].killed; };

  // Sessions live on hosts that stayed up must still be live; the ones on a killed host are gone.
  const auto check_survivors = [&] {
    for (auto it = live.begin(); it != live.end();) {
      const std::string& host = home[it->first];
      if (hosts[host].killed) {
        it = live.erase(it);
        continue;
      }
      if (!is_live_state(cluster.state_of(host, it->second))) {
        ++result.lost_on_up_hosts;
        it = live.erase(it);
        continue;
      }
      ++it;
    }
  };

  // Faults in turn: kill -9 a host (restarted halfway to the next), drain one (undrained halfway).
  struct Fault {
    std::string host;
    bool kill = false;
    int undo_at = -1;
  };
  std::optional<Fault> fault;
  int fault_number = 0;
  const auto pick_host = [&] {
    std::vector<std::string> ids;
    for (const auto& [id, state] : hosts) ids.push_back(id);
    return ids[std::uniform_int_distribution<std::size_t>(0, ids.size() - 1)(random)];
  };

  const auto begin = Clock::now();
  std::uniform_int_distribution<int> pick_uid(0, options.uids - 1);
  for (int call = 0; call < options.calls; ++call) {
    // The fault schedule.
    if (fault && call == fault->undo_at) {
      if (fault->kill) {
        cluster.restart_host(fault->host);
        hosts[fault->host].killed = false;
        ++result.restarts;
        // HAProxy sees it again after its next checks.
        cluster.wait_server_status("host_" + fault->host, fault->host, "UP", std::chrono::seconds(10));
      } else {
        cluster.admin_post(fault->host, "/api/undrain");
        hosts[fault->host].drained = false;
      }
      fault.reset();
      check_survivors();
    }
    if (!fault && call > 0 && call % options.fault_every == 0) {
      fault = Fault{pick_host(), fault_number++ % 2 == 0, call + options.fault_every / 2};
      if (fault->kill) {
        cluster.signal_host(fault->host, SIGKILL);
        hosts[fault->host].killed = true;
        ++result.kills;
      } else {
        cluster.admin_post(fault->host, "/api/drain");
        hosts[fault->host].drained = true;
        ++result.drains;
      }
      check_survivors();
    }

    // Sessions end (participants finish) so that about three quarters of the up hosts' slots stay taken.
    int capacity = 0;
    for (const auto& [id, state] : hosts) capacity += state.killed ? 0 : 1;
    capacity *= std::max(1, options.slots_per_host);
    while (!live.empty() && static_cast<int>(live.size()) * 4 >= capacity * 3) {
      auto it = live.begin();
      std::advance(it, std::uniform_int_distribution<std::size_t>(0, live.size() - 1)(random));
      cluster.end_session(home[it->first], it->second);
      live.erase(it);
    }

    if (options.interval_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(options.interval_ms));

    // Could this call get a session? Known uid: only on its home; new uid: anywhere live and undrained.
    const std::string uid = "bench-" + std::to_string(pick_uid(random));
    const auto known = home.find(uid);
    bool eligible = false;
    if (known != home.end()) {
      const std::string& h = known->second;
      eligible = up(h) && (live.count(uid) == 1 || (!hosts[h].drained && has_free_slot(cluster, h)));
    } else {
      for (const auto& [id, state] : hosts) eligible = eligible || (up(id) && !state.drained && has_free_slot(cluster, id));
    }

    const test::StartResult started = cluster.start("uid=" + uid);
    ++result.statuses[started.response.status];
    const bool served = started.response.status == 302 && !started.token.empty();
    if (eligible) {
      ++result.eligible;
      result.eligible_served += served ? 1 : 0;
      if (known == home.end()) {
        ++result.new_eligible;
        result.new_served += served ? 1 : 0;
      }
    }
    if (served) {
      if (known != home.end() && known->second != started.host) ++result.duplicates;  // a second home
      home.emplace(uid, started.host);
      if (tokens_seen.insert(started.token).second) ++result.sessions_started;
      live[uid] = started.token;
    }
    ++result.calls;
  }
  check_survivors();
  result.seconds = ms_between(begin, Clock::now()) / 1000.0;

  // The hosts' own records: one host per uid, ever.
  for (const auto& [uid, where] : homes_in_indexes(cluster)) result.duplicates += where.size() > 1 ? 1 : 0;
  return result;
}

}  // namespace rfbsim::bench
