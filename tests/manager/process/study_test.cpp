// SPDX-License-Identifier: GPL-2.0-or-later
// A study session through sim_manager: the link's completion codes reach sim_rfb, the task's outcome comes
// back over the pipe into the status the page polls and into the index, and the session's folder holds its
// data, with the participant's address (from the relay's PROXY line) hashed under the study's key.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "manager_process.hpp"
#include "record/digest.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using nlohmann::json;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::WsRfbBridge;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;

TEST_CASE("a timed-out task reaches the page's status, the index and the session's data with the link's code",
          "[manager][study][waits]") {
  TempDir data;
  ::setenv("RFBSIM_ADDRESS_KEY", "study-key-for-the-test", 1);  // inherited by the manager and its sessions
  // A 2 s task, and 2 s of grace after it instead of the warehouse's 15 (sim_rfb --end-grace).
  ManagerUnderTest manager(data.path(), with_small_sessions({"--session-arg", "--time-limit", "--session-arg", "2",
                                                             "--session-arg", "--end-grace", "--session-arg", "2"}));
  ::unsetenv("RFBSIM_ADDRESS_KEY");
  const std::string token = token_from_redirect(manager.start("uid=study-1&scenario=warehouse&t1=WELL-DONE&t2=TOO-LATE"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  const auto before = json::parse(manager.get("/s/" + token + "/status").body);
  CHECK(before["uid"] == "study-1");
  CHECK(before["outcome"].is_null());
  CHECK(before["code"].is_null());

  {
    // The viewer starts the task's clock; 2 s later the time is up.
    WsRfbBridge bridge(manager.ws_url(token));
    RfbTestClient client("127.0.0.1", bridge.port());
    REQUIRE(client.wait_for_updates(1, 20s));
    REQUIRE(rfbsim::test::eventually(
        [&] {
          client.pump_until([] { return false; }, 50ms);
          return json::parse(manager.get("/s/" + token + "/status").body)["outcome"] == "timeout";
        },
        20s));
  }
  const auto after = json::parse(manager.get("/s/" + token + "/status").body);
  CHECK(after["code"] == "TOO-LATE");
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  CHECK(row->params.find("\"t1\":\"WELL-DONE\"") != std::string::npos);

  // session.json and events.jsonl in the session's folder tell the same.
  const std::filesystem::path folder = row->data_path;
  REQUIRE(rfbsim::test::eventually(
      [&] {
        std::ifstream in(folder / "session.json");
        if (!in) return false;
        const json session = json::parse(in, nullptr, false);
        return !session.is_discarded() && session["outcome"] == "timeout";
      },
      10s));
  const json session = json::parse(std::ifstream(folder / "session.json"));
  CHECK(session["uid"] == "study-1");
  CHECK(session["end_grace_s"] == 2.0);
  CHECK(session["scenario"] == "warehouse");
  CHECK(session["completion"]["code"] == "TOO-LATE");
  CHECK(session["codes"]["success"] == "WELL-DONE");
  std::ifstream events(folder / "events.jsonl");
  std::string line;
  std::string connect_address;
  while (std::getline(events, line)) {
    const json event = json::parse(line);
    if (event["type"] == "client" && event["event"] == "connect") connect_address = event["address"];
  }
  // The bridge connected from 127.0.0.1; the relay named that address in its PROXY line.
  CHECK(connect_address == rfbsim::sim::hash_address("study-key-for-the-test", "127.0.0.1"));

  // The session ends by itself after the grace period: finished, with the outcome kept in the index.
  const bool finished = manager.wait_for_state(token, "finished", 40s);
  INFO("state: " << manager.state_of(token) << ", log: " << [&] { std::ifstream log(folder / "session.log"); std::stringstream s; s << log.rdbuf(); return s.str(); }());
  REQUIRE(finished);
  const auto status = json::parse(manager.get("/s/" + token + "/status").body);
  CHECK(status["outcome"] == "timeout");
  CHECK(status["code"] == "TOO-LATE");
}
