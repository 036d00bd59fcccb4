// SPDX-License-Identifier: GPL-2.0-or-later
// The /start policy decided from its inputs alone: no server, no socket, time passed in.
#include <catch2/catch.hpp>

#include "admission/link_signature.hpp"
#include "admission/start_admission.hpp"

using rfbsim::manager::ManagerConfig;
using rfbsim::manager::Rejection;
using rfbsim::manager::sign_query;
using rfbsim::manager::StartAdmission;
using rfbsim::manager::StartDecision;
using Kind = rfbsim::manager::StartDecision::Kind;

namespace {

const auto kNow = std::chrono::steady_clock::time_point{} + std::chrono::hours(1);
constexpr long long kUnixNow = 1'800'000'000;

StartDecision decide_once(const ManagerConfig& config, const std::string& query) {
  StartAdmission admission(config);
  return admission.decide(query, "192.0.2.1", kNow, kUnixNow);
}

}  // namespace

TEST_CASE("admission: a plain link is admitted with its uid and scenario") {
  const ManagerConfig config;
  const StartDecision decision = decide_once(config, "uid=p01&scenario=lab");
  REQUIRE(decision.kind == Kind::kAdmitted);
  CHECK(decision.request->uid == "p01");
  CHECK(decision.request->scenario == "lab");
}

TEST_CASE("admission: camera is admitted unless allow_camera_param is off, then refused with a 400") {
  ManagerConfig config;
  const StartDecision allowed = decide_once(config, "uid=p01&scenario=lab&camera=first_person");
  REQUIRE(allowed.kind == Kind::kAdmitted);
  CHECK(allowed.request->overrides == std::vector<std::pair<std::string, std::string>>{{"camera", "first_person"}});
  config.allow_camera_param = false;
  for (const char* query : {"uid=p01&scenario=lab&camera=first_person", "uid=p01&camera=third_person"}) {
    CAPTURE(query);
    const StartDecision refused = decide_once(config, query);
    REQUIRE(refused.kind == Kind::kRefused);
    CHECK(refused.status == 400);
    CHECK(refused.rejection == Rejection::kBadRequest);
    CHECK(refused.message.find("camera is not offered here") != std::string::npos);
  }
  CHECK(decide_once(config, "uid=p01&scenario=lab").kind == Kind::kAdmitted);
}

TEST_CASE("admission: a malformed query, a bad parameter and an unknown scenario are 400s that say why") {
  const ManagerConfig config;
  for (const char* query : {"uid=p%ZZ", "uid=p 01", "uid=p01&scenario=moon", "scenario=lab"}) {
    CAPTURE(query);
    const StartDecision decision = decide_once(config, query);
    REQUIRE(decision.kind == Kind::kRefused);
    CHECK(decision.status == 400);
    CHECK(decision.rejection == Rejection::kBadRequest);
    CHECK(decision.title == "This link is not valid");
    CHECK_FALSE(decision.message.empty());
  }
}

TEST_CASE("admission: with a link secret only signed links pass, and the signature is checked first") {
  ManagerConfig config;
  config.link_secret = "a secret of the study's own";
  // An unsigned link with a bad scenario learns only that its signature is wrong.
  const StartDecision unsigned_link = decide_once(config, "uid=p01&scenario=moon");
  REQUIRE(unsigned_link.kind == Kind::kRefused);
  CHECK(unsigned_link.status == 403);
  CHECK(unsigned_link.rejection == Rejection::kBadSignature);
  CHECK(unsigned_link.message.find("signature") != std::string::npos);

  CHECK(decide_once(config, sign_query("uid=p01&scenario=lab", config.link_secret)).kind == Kind::kAdmitted);
  CHECK(decide_once(config, sign_query("uid=p01&scenario=lab", "another secret")).kind == Kind::kRefused);
}

TEST_CASE("admission: a link's expiry is required when configured, and an expired link is 410") {
  ManagerConfig config;
  config.link_secret = "a secret of the study's own";
  config.require_link_expiry = true;
  const StartDecision without = decide_once(config, sign_query("uid=p01", config.link_secret));
  REQUIRE(without.kind == Kind::kRefused);
  CHECK(without.status == 403);
  CHECK(without.message.find("expiry") != std::string::npos);

  const std::string later = std::to_string(kUnixNow + 60);
  const std::string earlier = std::to_string(kUnixNow - 1);
  CHECK(decide_once(config, sign_query("uid=p01&exp=" + later, config.link_secret)).kind == Kind::kAdmitted);
  const StartDecision expired = decide_once(config, sign_query("uid=p01&exp=" + earlier, config.link_secret));
  REQUIRE(expired.kind == Kind::kRefused);
  CHECK(expired.status == 410);
  CHECK(expired.title == "This link has expired");
}

TEST_CASE("admission: each address has its own /start bucket - an empty one is told when to retry") {
  ManagerConfig config;
  config.abuse.start_burst = 2;
  config.abuse.start_per_minute = 6;  // a token every 10 s
  StartAdmission admission(config);
  CHECK(admission.decide("uid=p01", "192.0.2.1", kNow, kUnixNow).kind == Kind::kAdmitted);
  CHECK(admission.decide("uid=p01", "192.0.2.1", kNow, kUnixNow).kind == Kind::kAdmitted);
  const StartDecision limited = admission.decide("uid=p01", "192.0.2.1", kNow, kUnixNow);
  REQUIRE(limited.kind == Kind::kRateLimited);
  CHECK(limited.retry_after == std::chrono::seconds(10));
  // Even a bad link costs a token: the bucket is checked before anything is parsed.
  CHECK(admission.decide("uid=p01", "192.0.2.1", kNow + std::chrono::seconds(10), kUnixNow).kind ==
        Kind::kAdmitted);
  CHECK(admission.decide("not a query%", "198.51.100.7", kNow, kUnixNow).kind == Kind::kRefused);
  CHECK(admission.decide("uid=p02", "198.51.100.7", kNow, kUnixNow).kind == Kind::kAdmitted);
}

TEST_CASE("admission: a video link's yoke_uid needs signed links, and condition video needs sim_rfb") {
  ManagerConfig config;
  CHECK(decide_once(config, "uid=b1&scenario=lab&condition=video").kind == Kind::kAdmitted);
  const StartDecision unsigned_pin = decide_once(config, "uid=b1&scenario=lab&condition=video&yoke_uid=a1");
  REQUIRE(unsigned_pin.kind == Kind::kRefused);
  CHECK(unsigned_pin.status == 400);
  CHECK(unsigned_pin.message.find("yoke_uid is offered only on signed links") != std::string::npos);
  config.link_secret = "s3cret";
  const StartDecision signed_pin =
      decide_once(config, sign_query("uid=b1&scenario=lab&condition=video&yoke_uid=a1", config.link_secret));
  REQUIRE(signed_pin.kind == Kind::kAdmitted);
  CHECK(signed_pin.request->yoke_uid == "a1");
  ManagerConfig program;
  program.session_kind = rfbsim::manager::SessionKind::kRfb;
  program.scenarios.clear();
  const StartDecision not_sim = decide_once(program, "uid=b1&condition=video");
  REQUIRE(not_sim.kind == Kind::kRefused);
  CHECK(not_sim.message.find("only sim_rfb sessions are recorded to be replayed") != std::string::npos);
}
