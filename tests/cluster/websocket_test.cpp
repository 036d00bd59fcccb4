// SPDX-License-Identifier: GPL-2.0-or-later
// A participant's WebSocket through HAProxy (ws://balancer/<host>/s/<token>/ws) stays up for 60 s and keeps
// showing frames: HAProxy's tunnel timeout and the managers' keep-alive pings let a long session through.
#include <catch2/catch.hpp>

#include <chrono>

#include "cluster_under_test.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ClusterUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::WsRfbBridge;

TEST_CASE("a WebSocket through HAProxy stays up for 60 s and shows frames all along", "[cluster][long][waits]") {
  ClusterUnderTest cluster({.hosts = 3, .max_sessions = 1, .rate_limit = false,
                            .config_yaml = rfbsim::test::minimal_sessions_yaml()});
  const auto started = cluster.start("uid=ws-1");
  REQUIRE(started.response.status == 302);

  WsRfbBridge bridge("ws://127.0.0.1:" + std::to_string(cluster.port()) + "/" + started.host + "/s/" +
                     started.token + "/ws");
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(1, 20s));
  CHECK(client.width() == 640);  // rfbsim_minimal's picture, relayed by the manager through HAProxy
  CHECK(client.height() == 480);

  // Every 10 s of the minute, new frames arrived (the scene is animated) and the socket is still open.
  const auto begin = std::chrono::steady_clock::now();
  int windows_with_frames = 0;
  for (int window = 0; window < 6; ++window) {
    const std::uint64_t before = client.updates();
    client.pump_until([] { return false; }, 10s);
    if (client.updates() > before + 5) ++windows_with_frames;
    INFO("window " << window << ": " << client.updates() - before << " updates");
    CHECK(client.connected());
  }
  CHECK(std::chrono::steady_clock::now() - begin >= 60s);
  CHECK(windows_with_frames == 6);
  CHECK(bridge.last().opened);
  CHECK(bridge.last().close_code == -1);  // never closed
  CHECK(cluster.state_of(started.host, started.token) == "running");
}
