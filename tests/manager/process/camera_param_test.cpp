// SPDX-License-Identifier: GPL-2.0-or-later
// The link's camera through sim_manager: first_person reaches the session's sim_rfb and its session.json; a
// bad value, and any value where the study forbids the parameter (allow_camera_param false), get a 400.
#include <catch2/catch.hpp>

#include <fstream>
#include <nlohmann/json.hpp>

#include "manager_process.hpp"

using namespace std::chrono_literals;
using nlohmann::json;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;

namespace {

// session.json of the session behind `token`, once sim_rfb has written it.
json session_json(const ManagerUnderTest& manager, const std::string& token) {
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  const std::filesystem::path file = std::filesystem::path(row->data_path) / "session.json";
  REQUIRE(rfbsim::test::eventually([&] { return std::filesystem::exists(file); }, 20s));
  return json::parse(std::ifstream(file));
}

}  // namespace

TEST_CASE("a link with camera=first_person gives a first-person session, and a bad camera gets a 400", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::small_session_args());
  const std::string token = token_from_redirect(manager.start("uid=cam-1&scenario=lab&camera=first_person"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  const json session = session_json(manager, token);
  CHECK(session["camera"] == "first_person");
  CHECK(session["parameters"]["camera"] == "first_person");
  CHECK(manager.row_for_token(token)->params.find("\"camera\":\"first_person\"") != std::string::npos);

  // Without the parameter: the scenario's view, which for the lab is the third-person one.
  const std::string plain = token_from_redirect(manager.start("uid=cam-2&scenario=lab"));
  REQUIRE(manager.wait_for_state(plain, "running"));
  CHECK(session_json(manager, plain)["camera"] == "third_person");

  const auto bad = manager.start("uid=cam-3&scenario=lab&camera=overhead");
  CHECK(bad.status == 400);
  CHECK(bad.body.find("camera &#39;overhead&#39; is not valid") != std::string::npos);
}

TEST_CASE("a study with allow_camera_param false refuses any camera in a link with a 400", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::with_small_sessions({"--allow-camera-param", "false"}));
  for (const char* view : {"first_person", "third_person"}) {
    INFO(view);
    const auto refused = manager.start(std::string("uid=cam-4&scenario=lab&camera=") + view);
    CHECK(refused.status == 400);
    CHECK(refused.body.find("camera is not offered here") != std::string::npos);
  }
  // Links without it still start sessions.
  const std::string token = token_from_redirect(manager.start("uid=cam-5&scenario=lab"));
  CHECK(manager.wait_for_state(token, "running"));
}
