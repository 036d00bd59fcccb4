// SPDX-License-Identifier: GPL-2.0-or-later
// Faults through HAProxy: a host killed with SIGKILL is marked down within 5 s, its participants get the
// "session lost" answers, new uids go elsewhere and the other hosts' sessions go on; across that host's restart
// and an HAProxy reload no uid ever gets a second session (the hosts' own indexes, merged, say so).
#include <catch2/catch.hpp>
#include <signal.h>
#include <sqlite3.h>

#include <chrono>
#include <map>
#include <set>
#include <string>
#include <thread>

#include "cluster_under_test.hpp"
#include "manager_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ClusterUnderTest;
using rfbsim::test::StartResult;

namespace {

// Every (uid, host) session row of every host's own index.
std::multimap<std::string, std::string> sessions_by_uid(const ClusterUnderTest& cluster) {
  std::multimap<std::string, std::string> rows;
  for (const auto& host : cluster.hosts()) {
    sqlite3* db = nullptr;
    const std::string file = (host.data / "sessions.db").string();
    REQUIRE(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK);
    sqlite3_busy_timeout(db, 2000);
    sqlite3_stmt* statement = nullptr;
    REQUIRE(sqlite3_prepare_v2(db, "SELECT uid FROM sessions", -1, &statement, nullptr) == SQLITE_OK);
    while (sqlite3_step(statement) == SQLITE_ROW) {
      rows.emplace(reinterpret_cast<const char*>(sqlite3_column_text(statement, 0)), host.id);
    }
    sqlite3_finalize(statement);
    sqlite3_close(db);
  }
  return rows;
}

}  // namespace

TEST_CASE("a killed host is marked down within 5 s and its participants see session lost - no uid gets a second "
          "session across its restart and an HAProxy reload",
          "[cluster][waits]") {
  ClusterUnderTest cluster({.hosts = 3, .max_sessions = 2, .rate_limit = false,
                            .config_yaml = rfbsim::test::minimal_sessions_yaml()});

  // The victim's session, and a bystander on another host.
  const StartResult victim = cluster.start("uid=victim");
  REQUIRE(victim.response.status == 302);
  const std::string v = victim.host;
  StartResult bystander;
  std::string bystander_uid;
  for (int i = 0; i < 3 && (bystander.host.empty() || bystander.host == v); ++i) {
    bystander_uid = "by-" + std::to_string(i);
    bystander = cluster.start("uid=" + bystander_uid, "/h" + std::to_string(i + 1) + "/start");
  }
  REQUIRE(bystander.response.status == 302);
  REQUIRE(bystander.host != v);
  REQUIRE(rfbsim::test::eventually([&] { return cluster.state_of(bystander.host, bystander.token) == "running"; },
                                   20s));

  // kill -9: HAProxy marks it down within 5 s, in its own backend and in the pool.
  const auto killed_at = std::chrono::steady_clock::now();
  cluster.signal_host(v, SIGKILL);
  CHECK(cluster.wait_server_status("host_" + v, v, "DOWN", 5s));
  CHECK(cluster.wait_server_status(
      "pool", v, "DOWN",
      std::chrono::duration_cast<std::chrono::milliseconds>(5s - (std::chrono::steady_clock::now() - killed_at))));

  // Its participant: the status poll gets a final "lost", the page a clear "session lost".
  const auto status = cluster.get("/" + v + "/s/" + victim.token + "/status");
  CHECK(status.status == 410);
  CHECK(status.body == R"({"state":"lost","ends_as":"lost"})");
  const auto page = cluster.get("/" + v + "/s/" + victim.token + "/");
  CHECK(page.status == 503);
  CHECK(page.body.find("Session lost") != std::string::npos);

  // New uids go elsewhere; the bystander goes on; the victim's uid is not started again anywhere.
  const StartResult newcomer = cluster.start("uid=after-kill");
  CHECK(newcomer.response.status == 302);
  CHECK(newcomer.host != v);
  CHECK(cluster.state_of(bystander.host, bystander.token) == "running");
  const StartResult orphan = cluster.start("uid=victim");
  INFO("victim's /start while its host is down: " << orphan.response.raw.substr(0, 300));
  CHECK(orphan.token.empty());

  // The host comes back. The killed session counts as interrupted, not completed (a crash does not burn the
  // participant's link), so the uid may start again, but only on its home: the registry's record is for good.
  cluster.restart_host(v);
  REQUIRE(cluster.wait_server_status("host_" + v, v, "UP", 10s));
  REQUIRE(cluster.wait_server_status("pool", v, "UP", 10s));
  const StartResult returned = cluster.start("uid=victim");
  INFO("victim's /start after the restart: " << returned.response.raw.substr(0, 300));
  REQUIRE(returned.response.status == 302);
  CHECK(returned.host == v);
  CHECK(returned.token != victim.token);

  // HAProxy reloads (new workers, fresh check state): still one session per uid, live ones rejoin.
  cluster.reload_haproxy();
  std::this_thread::sleep_for(1s);
  for (const auto& host : cluster.hosts()) CHECK(cluster.wait_server_status("pool", host.id, "UP", 10s));
  const StartResult by_again = cluster.start("uid=" + bystander_uid);
  CHECK(by_again.host == bystander.host);
  CHECK(by_again.token == bystander.token);
  CHECK(cluster.start("uid=after-kill").token == newcomer.token);
  const StartResult victim_again = cluster.start("uid=victim");
  CHECK(victim_again.host == v);
  CHECK(victim_again.token == returned.token);

  // The hosts' own records: every uid has sessions on one host only; only the victim has two (the killed one
  // and its restart, both on its home).
  const auto rows = sessions_by_uid(cluster);
  std::set<std::string> uids;
  for (const auto& [uid, host] : rows) uids.insert(uid);
  for (const std::string& uid : uids) {
    INFO("uid " << uid);
    std::set<std::string> homes;
    const auto [begin, end] = rows.equal_range(uid);
    for (auto it = begin; it != end; ++it) homes.insert(it->second);
    CHECK(homes.size() == 1);
    CHECK(rows.count(uid) == (uid == "victim" ? 2U : 1U));
  }
  CHECK(uids.count("victim") == 1);
}
