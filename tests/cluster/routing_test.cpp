// SPDX-License-Identifier: GPL-2.0-or-later
// Routing through HAProxy: a uid's /start always reaches its session's host and token, its page and status
// answer under the host's prefix, and an ended uid says "already completed" whichever way it is asked.
#include <catch2/catch.hpp>

#include <chrono>

#include "cluster_under_test.hpp"
#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ClusterUnderTest;
using rfbsim::test::StartResult;
using rfbsim::test::RfbTestClient;
using rfbsim::test::WsRfbBridge;

TEST_CASE("a uid reaches the same host and token every time by any route and once ended is completed everywhere",
          "[cluster]") {
  ClusterUnderTest cluster({.hosts = 3, .max_sessions = 2, .rate_limit = false,
                            .config_yaml = rfbsim::test::minimal_sessions_yaml()});

  const StartResult first = cluster.start("uid=same-1");
  INFO("statuses of the first /start: " << first.statuses.size() << ", last " << first.response.status << "\n"
                                        << first.response.raw);
  REQUIRE(first.response.status == 302);
  REQUIRE(first.token.size() == 32);
  // The session's host is the one the pool picked: a free host that the registry made the uid's owner.
  CHECK(first.host == first.first_host);
  CHECK(first.response.headers.at("location") == "/" + first.host + "/s/" + first.token + "/");

  // 10 of 10 times: the same host, the same token.
  int same = 0;
  for (int i = 0; i < 10; ++i) {
    const StartResult again = cluster.start("uid=same-1");
    same += again.response.status == 302 && again.host == first.host && again.token == first.token ? 1 : 0;
  }
  CHECK(same == 10);

  // The page and its status live under the host's prefix, through the one public port.
  CHECK(cluster.get("/" + first.host + "/s/" + first.token + "/").status == 200);
  CHECK(rfbsim::test::eventually([&] { return cluster.state_of(first.host, first.token) == "running"; }, 20s));

  // Every host's own /start sends the uid to its owner (303), which rejoins it: a re-opened link on any route.
  for (const auto& host : cluster.hosts()) {
    const StartResult via = cluster.start("uid=same-1", "/" + host.id + "/start");
    INFO("via " << host.id << ": " << via.response.raw.substr(0, 300));
    CHECK(via.response.status == 302);
    CHECK(via.host == first.host);
    CHECK(via.token == first.token);
    if (host.id != first.host) CHECK(via.statuses.front() == 303);
  }

  // The participant sees the session through the balancer (a picture reached it: the link is spent), then
  // the researcher ends it: from then on "already completed" through the pool and through every host.
  {
    WsRfbBridge bridge("ws://127.0.0.1:" + std::to_string(cluster.port()) + "/" + first.host + "/s/" + first.token +
                       "/ws");
    RfbTestClient client("127.0.0.1", bridge.port());
    // The manager counts the link spent after its first KiB reached the browser; small updates of the
    // animated scene get there within a few frames.
    REQUIRE(client.pump_until([&] { return bridge.last().bytes_to_client > 4096; }, 20s));
  }
  REQUIRE(cluster.end_session(first.host, first.token));
  REQUIRE(rfbsim::test::eventually(
      [&] {
        const std::string state = cluster.state_of(first.host, first.token);
        return !state.empty() && state != "starting" && state != "running" && state != "ending";
      },
      20s));
  const StartResult pooled = cluster.start("uid=same-1");
  CHECK(pooled.response.status == 409);
  CHECK(pooled.response.body.find("already been completed") != std::string::npos);
  for (const auto& host : cluster.hosts()) {
    const StartResult via = cluster.start("uid=same-1", "/" + host.id + "/start");
    INFO("via " << host.id << ": " << via.response.raw.substr(0, 300));
    CHECK(via.response.status == 409);
    CHECK(via.response.body.find("already been completed") != std::string::npos);
    CHECK(via.token.empty());
  }
}
