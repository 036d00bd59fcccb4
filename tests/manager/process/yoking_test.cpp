// SPDX-License-Identifier: GPL-2.0-or-later
// The video condition's pairing through a real sim_manager (issue 33): with yoke_policy by_participant a
// watcher is shown one walker's sessions for all their links, the next watcher the next walker; a signed link
// may pin the walker with yoke_uid, and gets a 503 when that walker's session is taken. Every link is signed
// (link_secret), as a study that pins walkers runs. The choice's rules one by one are unit-tested
// (tests/manager/unit/sessions/yoking_test.cpp); this checks them on the index's real rows.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using nlohmann::json;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;

namespace {

constexpr const char* kSecret = "yoking-test-link-secret-0123";

// `query` signed by sim_manager's own --sign.
std::string signed_link(const std::string& query) {
  const auto signed_query =
      rfbsim::test::run_to_exit(rfbsim::test::sim_manager_path(), {"--link-secret", kSecret, "--sign", query});
  REQUIRE(signed_query.status == 0);
  return signed_query.output.substr(0, signed_query.output.find('\n'));
}

// Opens `token`'s session with a client until its first picture (the link is spent), then the researcher ends
// it; returns its index id.
std::int64_t open_then_end(const ManagerUnderTest& manager, const std::string& token) {
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  {
    rfbsim::test::WsRfbBridge bridge(manager.ws_url(token));
    rfbsim::test::RfbTestClient client("127.0.0.1", bridge.port());
    REQUIRE(client.wait_for_updates(1, 20s));
    REQUIRE(manager.wait_for_row(token, [](const rfbsim::test::IndexRow& row) { return !row.spent_at.empty(); }, 10s));
  }
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  REQUIRE(manager.end_session(row->id, rfbsim::test::kAdminToken).status == 200);
  REQUIRE(manager.wait_for_state(token, "ended", 30s));
  return row->id;
}

// A walker's session of `scenario`, opened and ended; its id.
std::int64_t walk(const ManagerUnderTest& manager, const std::string& uid, const std::string& scenario) {
  return open_then_end(manager, token_from_redirect(manager.start(signed_link("uid=" + uid + "&scenario=" + scenario))));
}

// The id of the session a watcher's token was shown.
std::int64_t yoked_to(const ManagerUnderTest& manager, const std::string& token) {
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  const auto response = manager.get("/api/sessions", {{"Authorization", std::string("Bearer ") + rfbsim::test::kAdminToken}});
  REQUIRE(response.status == 200);
  const json all = json::parse(response.body);
  for (const char* list : {"live", "recent"}) {
    for (const json& entry : all[list]) {
      if (entry["id"] == row->id) {
        CHECK(entry["condition"] == "video");
        return entry["yoked_to"].get<std::int64_t>();
      }
    }
  }
  FAIL("session " << row->id << " is not in /api/sessions");
  return 0;
}

}  // namespace

TEST_CASE("yoke_policy by_participant keeps a watcher on one walker, and a signed yoke_uid pins one", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(
      data.path(), rfbsim::test::with_small_sessions(rfbsim::test::without_abuse_limits(
                       {"--admin-token", rfbsim::test::kAdminToken, "--link-secret", kSecret, "--scenarios",
                        "lab,tutorial", "--allow-repeat", "true", "--yoke-policy", "by_participant"})));
  // Two walkers, each with a session of both scenarios; a1's lab session ends first, a2's tutorial before a1's.
  const std::int64_t a1_lab = walk(manager, "a1", "lab");
  const std::int64_t a2_lab = walk(manager, "a2", "lab");
  const std::int64_t a2_tutorial = walk(manager, "a2", "tutorial");
  const std::int64_t a1_tutorial = walk(manager, "a1", "tutorial");

  // b1's first link pairs them with a1, the first walker; their tutorial link shows a1's too, though a2's
  // tutorial session ended earlier.
  const std::string b1_lab = token_from_redirect(manager.start(signed_link("uid=b1&scenario=lab&condition=video")));
  CHECK(yoked_to(manager, b1_lab) == a1_lab);
  open_then_end(manager, b1_lab);
  const std::string b1_tutorial =
      token_from_redirect(manager.start(signed_link("uid=b1&scenario=tutorial&condition=video")));
  REQUIRE(b1_tutorial.size() == 32);
  CHECK(yoked_to(manager, b1_tutorial) == a1_tutorial);

  // b2 starts with the tutorial: a1 has their one paired watcher, so a2.
  const std::string b2_tutorial =
      token_from_redirect(manager.start(signed_link("uid=b2&scenario=tutorial&condition=video")));
  REQUIRE(b2_tutorial.size() == 32);
  CHECK(yoked_to(manager, b2_tutorial) == a2_tutorial);

  // b3: every walker is paired.
  CHECK(manager.start(signed_link("uid=b3&scenario=lab&condition=video")).status == 503);

  // A pinned walker: a1's lab session is b1's, so none; a2's lab session is free.
  CHECK(manager.start(signed_link("uid=c1&scenario=lab&condition=video&yoke_uid=a1")).status == 503);
  const std::string c1 = token_from_redirect(manager.start(signed_link("uid=c1&scenario=lab&condition=video&yoke_uid=a2")));
  REQUIRE(c1.size() == 32);
  CHECK(yoked_to(manager, c1) == a2_lab);
  // The pinned walker's uid is never recorded with the watcher.
  CHECK(manager.row_for_token(c1)->params.find("a2") == std::string::npos);
}
