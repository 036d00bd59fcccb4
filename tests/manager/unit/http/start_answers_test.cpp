// SPDX-License-Identifier: GPL-2.0-or-later
// What a participant's browser is answered for each outcome of /start, without a server.
#include <catch2/catch.hpp>

#include "http/start_answers.hpp"

using rfbsim::manager::answer_busy;
using rfbsim::manager::answer_go_home;
using rfbsim::manager::answer_home_undecided;
using rfbsim::manager::answer_refused_start;
using rfbsim::manager::answer_start_outcome;
using rfbsim::manager::Headers;
using rfbsim::manager::ManagerConfig;
using rfbsim::manager::PageAnswer;
using rfbsim::manager::Rejection;
using rfbsim::manager::StartDecision;
using rfbsim::manager::StartOutcome;

namespace {

std::string header(const PageAnswer& answer, const std::string& name) {
  for (const auto& [key, value] : answer.headers) {
    if (key == name) return value;
  }
  return "";
}

PageAnswer for_outcome(StartOutcome::Kind kind, const ManagerConfig& config = {}) {
  StartOutcome outcome;
  outcome.kind = kind;
  outcome.token = "0123456789abcdef0123456789abcdef";
  return answer_start_outcome(outcome, config);
}

}  // namespace

TEST_CASE("start answers: a started or joined session redirects into it, under the host's prefix and origin") {
  ManagerConfig config;
  config.public_url = "https://h2.example.org";
  config.path_prefix = "/h2";
  for (const auto kind : {StartOutcome::Kind::kStarted, StartOutcome::Kind::kJoined}) {
    const PageAnswer answer = for_outcome(kind, config);
    CHECK(answer.status == 302);
    CHECK(header(answer, "Location") == "https://h2.example.org/h2/s/0123456789abcdef0123456789abcdef/");
    CHECK_FALSE(answer.rejection);
  }
}

TEST_CASE("start answers: busy is a 503 to retry anywhere - a previous session ending is a 409 to retry here") {
  const PageAnswer busy = for_outcome(StartOutcome::Kind::kBusy);
  CHECK(busy.status == 503);
  CHECK(header(busy, "Retry-After") == "10");
  CHECK(busy.rejection == Rejection::kBusy);
  CHECK(answer_busy().status == 503);
  const PageAnswer ending = for_outcome(StartOutcome::Kind::kPreviousEnding);
  CHECK(ending.status == 409);
  CHECK(header(ending, "Retry-After") == "3");
  CHECK(for_outcome(StartOutcome::Kind::kCompleted).status == 409);
  CHECK(for_outcome(StartOutcome::Kind::kCompleted).rejection == Rejection::kCompleted);
  CHECK(for_outcome(StartOutcome::Kind::kFailed).status == 503);
  CHECK_FALSE(for_outcome(StartOutcome::Kind::kFailed).rejection);
  CHECK(answer_home_undecided().status == 503);
  CHECK(header(answer_home_undecided(), "Retry-After") == "5");
}

TEST_CASE("start answers: too many unspent sessions retry after the idle timeout, 1 to 60 s") {
  ManagerConfig config;
  config.idle_timeout = std::chrono::seconds(600);
  CHECK(header(for_outcome(StartOutcome::Kind::kTooManyUnspent, config), "Retry-After") == "60");
  config.idle_timeout = std::chrono::seconds(15);
  const PageAnswer answer = for_outcome(StartOutcome::Kind::kTooManyUnspent, config);
  CHECK(answer.status == 429);
  CHECK(header(answer, "Retry-After") == "15");
  CHECK(answer.rejection == Rejection::kUnspentLimit);
}

TEST_CASE("start answers: a refused link shows its reason - a rate-limited one when to retry - home is a 303") {
  StartDecision refused;
  refused.kind = StartDecision::Kind::kRefused;
  refused.status = 410;
  refused.rejection = Rejection::kBadSignature;
  refused.title = "This link has expired";
  refused.message = "The study link is no longer valid.";
  const PageAnswer answer = answer_refused_start(refused);
  CHECK(answer.status == 410);
  CHECK(answer.html.find("This link has expired") != std::string::npos);
  CHECK(answer.rejection == Rejection::kBadSignature);

  StartDecision limited;
  limited.kind = StartDecision::Kind::kRateLimited;
  limited.retry_after = std::chrono::seconds(7);
  CHECK(answer_refused_start(limited).status == 429);
  CHECK(header(answer_refused_start(limited), "Retry-After") == "7");

  const PageAnswer home = answer_go_home("h3", "uid=p01&scenario=lab");
  CHECK(home.status == 303);
  CHECK(header(home, "Location") == "/h3/start?uid=p01&scenario=lab");
  CHECK(home.html.find("uid=p01&amp;scenario=lab") != std::string::npos);
}
