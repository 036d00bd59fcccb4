// SPDX-License-Identifier: GPL-2.0-or-later
// Bad clients against a real sim_rfb process while a good libvncclient client watches; the process must
// keep serving, answer /status.json, and still exit 0 on SIGTERM.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cmath>
#include <csignal>
#include <thread>

#include "eventually.hpp"
#include "misbehaving_clients.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"

namespace {

using namespace std::chrono_literals;
using rfbsim::test::eventually;
using rfbsim::test::RawSocket;
using rfbsim::test::RfbTestClient;

// The "clients" field of /status.json (NaN when the document does not answer).
double status_clients(int port) {
  return rfbsim::test::json_number(rfbsim::test::http_body(rfbsim::test::http_get(port, "/status.json")), "clients");
}

}  // namespace

TEST_CASE("sim_rfb survives garbage, a vanishing client and a bad WebSocket frame", "[robustness][process]") {
  rfbsim::test::SimProcess sim(rfbsim::test::sim_rfb_path(), {"--port", "0", "--width", "640", "--height", "480"});
  const int port = sim.port();
  RfbTestClient good("127.0.0.1", port);
  good.send_key('a', true);  // keep the avatar turning so that every rendered frame differs
  REQUIRE(good.wait_for_updates(2, 20s));

  const auto check_still_serving = [&] {
    CHECK(eventually([&] { return status_clients(port) == 1.0; }, 10s));
    CHECK(good.wait_for_updates(3, 20s));
    try {
      RfbTestClient fresh("127.0.0.1", port);
      CHECK(fresh.width() == 640);
      CHECK(fresh.wait_for_updates(1, 20s));
    } catch (const std::exception& e) {
      FAIL_CHECK("a new client could not connect: " << e.what());
    }
    CHECK(eventually([&] { return status_clients(port) == 1.0; }, 10s));
    CHECK(sim.running());
  };

  // Garbage instead of the RFB version.
  std::string garbage = rfbsim::test::random_bytes(512, 23);
  garbage[0] = 'Z';
  CHECK(rfbsim::test::server_closes_after(port, garbage, 10s));
  check_still_serving();

  // A client that resets the connection in the middle of four 1.2 MB Raw updates.
  CHECK(rfbsim::test::vanish_mid_update(port, 640, 480, 4, 4096));
  check_still_serving();

  // A WebSocket frame that claims 2^63-1 payload bytes, whose first bytes are no RFB version.
  {
    RawSocket socket(port);
    REQUIRE(rfbsim::test::raw_websocket_upgrade(socket, port).rfind("HTTP/1.1 101", 0) == 0);
    const std::uint32_t mask = 0x01020304U;
    auto frame = rfbsim::test::ws_header_claiming(0x7fffffffffffffffULL, mask);
    const auto payload = rfbsim::test::ws_mask(std::vector<std::uint8_t>(12, 'X'), mask);
    frame.insert(frame.end(), payload.begin(), payload.end());
    REQUIRE(socket.send_all(frame));
    bool closed = false;
    socket.read_until_closed(10s, &closed);
    CHECK(closed);
  }
  check_still_serving();

  // The status document still answers, and SIGTERM is a clean exit.
  const std::string status = rfbsim::test::http_get(port, "/status.json");
  CHECK(status.rfind("HTTP/1.1 200", 0) == 0);
  CHECK(std::isfinite(rfbsim::test::json_number(rfbsim::test::http_body(status), "tick")));
  good.send_key('a', false);
  const int exit_status = sim.stop(SIGTERM, 10s);
  REQUIRE(exit_status != -1);
  CHECK(WIFEXITED(exit_status));
  CHECK(WEXITSTATUS(exit_status) == 0);
}
