// SPDX-License-Identifier: GPL-2.0-or-later
// Capacity through HAProxy: a full host (its agent says drain) gets no new uids while its own uids rejoin it;
// with every host full the participant sees the busy page with Retry-After; an operator-drained host keeps its
// live session and takes no new one even with a free slot, until it is undrained.
#include <catch2/catch.hpp>

#include <chrono>
#include <map>
#include <string>

#include "cluster_under_test.hpp"
#include "manager_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ClusterUnderTest;
using rfbsim::test::StartResult;

namespace {

// Where the pool's hash sends `uid` now: the host that answers /healthz?uid=... (HAProxy names it).
std::string hashed_host(const ClusterUnderTest& cluster, const std::string& uid) {
  const auto response = cluster.get("/healthz?uid=" + uid);
  const auto served = response.headers.find("x-rfbsim-host");
  return served == response.headers.end() ? "" : served->second;
}

bool is_busy_page(const StartResult& result) {
  return result.response.status == 503 && result.response.headers.count("retry-after") == 1 &&
         result.response.body.find("busy") != std::string::npos;
}

}  // namespace

TEST_CASE("a full host sends new uids elsewhere while its own rejoin - all full is the busy page - a drained host "
          "keeps its session and takes no new one",
          "[cluster][waits]") {
  ClusterUnderTest cluster({.hosts = 3, .max_sessions = 2, .rate_limit = false,
                            .config_yaml = rfbsim::test::minimal_sessions_yaml()});
  const std::string a = "h1";

  // Before anything is full: uids whose hash lands on h1 (every host has the same weight now).
  std::vector<std::string> hashed_to_a;
  for (int i = 0; i < 200 && hashed_to_a.size() < 2; ++i) {
    const std::string uid = "cap-" + std::to_string(i);
    if (hashed_host(cluster, uid) == a) hashed_to_a.push_back(uid);
  }
  REQUIRE(hashed_to_a.size() == 2);

  // Fill h1 through its own prefix (its /start claims the uids for itself).
  std::map<std::string, std::string> tokens;  // uid -> token
  for (const std::string& uid : {std::string("full-a1"), std::string("full-a2")}) {
    const StartResult started = cluster.start("uid=" + uid, "/" + a + "/start");
    REQUIRE(started.response.status == 302);
    REQUIRE(started.host == a);
    tokens[uid] = started.token;
  }
  // Its agent now says drain: HAProxy stops hashing new uids to it.
  REQUIRE(cluster.wait_server_status("pool", a, "DRAIN", 5s));

  // A uid that hashed to h1 before goes elsewhere and gets a session there.
  const StartResult moved = cluster.start("uid=" + hashed_to_a[0]);
  INFO(moved.response.raw.substr(0, 300));
  REQUIRE(moved.response.status == 302);
  CHECK(moved.host != a);
  CHECK(moved.first_host != a);
  CHECK(hashed_host(cluster, hashed_to_a[1]) != a);

  // h1's own uids still rejoin it through the pool: another host answers 303 to /h1/start, h1 rejoins.
  for (const std::string& uid : {std::string("full-a1"), std::string("full-a2")}) {
    const StartResult rejoined = cluster.start("uid=" + uid);
    CHECK(rejoined.response.status == 302);
    CHECK(rejoined.host == a);
    CHECK(rejoined.token == tokens[uid]);
    CHECK(rejoined.statuses.front() == 303);
  }
  CHECK(cluster.get("/" + a + "/s/" + tokens["full-a1"] + "/").status == 200);

  // Fill the other two hosts through their prefixes: 2 slots each, one taken by `moved`.
  std::map<std::string, std::vector<std::string>> fill_tokens;  // host -> tokens of its fill sessions
  int fill = 0;
  for (const std::string& host : {std::string("h2"), std::string("h3")}) {
    while (true) {
      const StartResult started = cluster.start("uid=fill-" + std::to_string(fill++), "/" + host + "/start");
      if (started.response.status != 302) {
        CHECK(started.response.status == 503);  // full: the busy page, nothing claimed
        break;
      }
      CHECK(started.host == host);
      fill_tokens[host].push_back(started.token);
      REQUIRE(fill < 10);
    }
  }
  for (const auto& host : cluster.hosts()) CHECK(cluster.wait_server_status("pool", host.id, "DRAIN", 5s));

  // Every host full: a new participant gets the busy page with Retry-After; a live one still rejoins.
  const StartResult busy = cluster.start("uid=late-1");
  INFO(busy.response.raw.substr(0, 400));
  CHECK(is_busy_page(busy));
  CHECK(cluster.start("uid=" + hashed_to_a[0]).token == moved.token);

  // Drain h3 after one of its sessions ended: a free slot, yet no new uid; the other session goes on.
  const std::string c = "h3";
  std::string kept_token;
  if (moved.host == c) {
    kept_token = moved.token;
    REQUIRE(cluster.end_session(c, fill_tokens[c].front()));
  } else {
    REQUIRE(fill_tokens[c].size() == 2);
    kept_token = fill_tokens[c][1];
    REQUIRE(cluster.end_session(c, fill_tokens[c][0]));
  }
  REQUIRE(cluster.wait_server_status("pool", c, "UP", 10s));
  const auto drained = cluster.admin_post(c, "/api/drain");
  CHECK(drained.status == 200);
  CHECK(drained.body.find("\"draining\":true") != std::string::npos);
  const auto health = cluster.get_direct(c, "/healthz");
  CHECK(health.status == 503);
  CHECK(health.body.find("draining") != std::string::npos);
  CHECK(rfbsim::test::eventually([&] { return cluster.server_status("pool", c).rfind("UP", 0) != 0; }, 5s, 100ms));
  CHECK(is_busy_page(cluster.start("uid=late-2")));
  const StartResult direct = cluster.start("uid=late-3", "/" + c + "/start");
  CHECK(direct.response.status == 503);  // a draining host claims nothing, even asked by name
  CHECK(cluster.state_of(c, kept_token) == "running");
  CHECK(cluster.get("/" + c + "/s/" + kept_token + "/").status == 200);

  // Undrained: it takes new uids again.
  CHECK(cluster.admin_post(c, "/api/undrain").status == 200);
  REQUIRE(cluster.wait_server_status("pool", c, "UP", 10s));
  const StartResult after = cluster.start("uid=late-2");
  CHECK(after.response.status == 302);
  CHECK(after.host == c);
}
