// SPDX-License-Identifier: GPL-2.0-or-later
// The video condition's choice of a watcher's source session (sessions/yoking.hpp), rule by rule.
#include <catch2/catch.hpp>

#include <chrono>
#include <set>

#include "sessions/yoking.hpp"

using rfbsim::manager::choose_yoke_source;
using rfbsim::manager::holds_watch_place;
using rfbsim::manager::may_be_shown;
using rfbsim::manager::Session;
using rfbsim::manager::SessionState;
using rfbsim::manager::WallTime;
using rfbsim::manager::YokeRequest;

namespace {

const WallTime kStart = WallTime{} + std::chrono::seconds(1'800'000'000);

// A walker's session of `scenario` that ran its course, its link spent, ended `ended_s` after kStart.
Session walked(std::int64_t id, const std::string& uid, const std::string& scenario, int ended_s) {
  Session s;
  s.id = id;
  s.uid = uid;
  s.scenario = scenario;
  s.host_id = "h1";
  s.state = SessionState::kFinished;
  s.created = kStart;
  s.spent_at = kStart + std::chrono::seconds(1);
  s.ended_at = kStart + std::chrono::seconds(ended_s);
  s.data_path = "/data/sessions/" + std::to_string(id) + "-" + uid;
  return s;
}

// A watcher's session of `scenario` shown session `source`.
Session watching(std::int64_t id, const std::string& uid, const std::string& scenario, std::int64_t source,
                 SessionState state = SessionState::kRunning) {
  Session s;
  s.id = id;
  s.uid = uid;
  s.scenario = scenario;
  s.host_id = "h1";
  s.state = state;
  s.condition = "video";
  s.yoked_to = source;
  s.created = kStart + std::chrono::seconds(100 + id);
  return s;
}

YokeRequest video_link(const std::string& watcher, const std::string& scenario) {
  YokeRequest request;
  request.watcher_uid = watcher;
  request.scenario = scenario;
  request.host_id = "h1";
  return request;
}

const auto kAllPresent = [](const Session&) { return true; };

std::int64_t chosen(const std::vector<Session>& sessions, const YokeRequest& request) {
  const auto choice = choose_yoke_source(sessions, request, kAllPresent);
  if (!choice.source) {
    INFO("none: " << choice.why_none);
    CHECK_FALSE(choice.why_none.empty());
    return 0;
  }
  return choice.source->id;
}

}  // namespace

TEST_CASE("yoking: only a spent interactive session of this host that ran its course may be shown") {
  Session s = walked(1, "a", "lab", 30);
  CHECK(may_be_shown(s, "h1"));
  CHECK_FALSE(may_be_shown(s, "h2"));
  for (const SessionState state : {SessionState::kExpired, SessionState::kIdle, SessionState::kEnded}) {
    s.state = state;
    CHECK(may_be_shown(s, "h1"));
  }
  for (const SessionState state : {SessionState::kCrashed, SessionState::kFailed, SessionState::kAbandoned,
                                   SessionState::kInterrupted, SessionState::kShutdown, SessionState::kRunning}) {
    s.state = state;
    CHECK_FALSE(may_be_shown(s, "h1"));
  }
  s = walked(1, "a", "lab", 30);
  s.spent_at.reset();
  CHECK_FALSE(may_be_shown(s, "h1"));
  s = walked(1, "a", "lab", 30);
  s.condition = "video";
  CHECK_FALSE(may_be_shown(s, "h1"));
  // A watcher holds their place while live or once it ran its course; a failed or abandoned one frees it.
  CHECK(holds_watch_place(watching(9, "b", "lab", 1)));
  CHECK(holds_watch_place(watching(9, "b", "lab", 1, SessionState::kFinished)));
  CHECK_FALSE(holds_watch_place(watching(9, "b", "lab", 1, SessionState::kAbandoned)));
  CHECK_FALSE(holds_watch_place(watching(9, "b", "lab", 1, SessionState::kFailed)));
}

TEST_CASE("yoking: the earliest-ended session of the scenario with room, then the next") {
  std::vector<Session> sessions = {walked(2, "a2", "lab", 50), walked(1, "a1", "lab", 60), walked(3, "a3", "warehouse", 10)};
  CHECK(chosen(sessions, video_link("b1", "lab")) == 2);  // ended first, though its id is higher
  sessions.push_back(watching(10, "b1", "lab", 2));
  CHECK(chosen(sessions, video_link("b2", "lab")) == 1);
  sessions.push_back(watching(11, "b2", "lab", 1));
  CHECK(chosen(sessions, video_link("b3", "lab")) == 0);  // each watched once: none (a 503)
  CHECK(chosen(sessions, video_link("b3", "warehouse")) == 3);
  // Two watchers allowed.
  YokeRequest two = video_link("b3", "lab");
  two.max_viewers = 2;
  CHECK(chosen(sessions, two) == 2);
  // A watcher whose session was abandoned (a link preview) freed its place.
  sessions[3].state = SessionState::kAbandoned;
  CHECK(chosen(sessions, video_link("b3", "lab")) == 2);
  // A recording no longer on disk is skipped.
  const auto only_1 = [](const Session& s) { return s.id == 1; };
  CHECK_FALSE(choose_yoke_source(sessions, video_link("b3", "lab"), only_1).source.has_value());
}

TEST_CASE("yoking: a watcher is shown the same session again, and never their own walk") {
  std::vector<Session> sessions = {walked(1, "a1", "lab", 50), walked(2, "a2", "lab", 60),
                                   watching(10, "b1", "lab", 2, SessionState::kFinished)};
  CHECK(chosen(sessions, video_link("b1", "lab")) == 2);  // not counted against themselves
  CHECK(chosen(sessions, video_link("a1", "lab")) == 0);  // a1 walked session 1; session 2 is b1's
  sessions.push_back(walked(3, "a3", "lab", 70));
  CHECK(chosen(sessions, video_link("a1", "lab")) == 3);
}

TEST_CASE("yoking: a signed link's yoke_uid picks that walker's session") {
  std::vector<Session> sessions = {walked(1, "a1", "lab", 50), walked(2, "a2", "lab", 60)};
  YokeRequest pinned = video_link("b1", "lab");
  pinned.pinned_uid = "a2";
  CHECK(chosen(sessions, pinned) == 2);
  sessions.push_back(watching(10, "b0", "lab", 2));
  CHECK(chosen(sessions, pinned) == 0);  // a2's only session is taken: not another walker's instead
  pinned.pinned_uid = "nobody";
  CHECK(chosen(sessions, pinned) == 0);
}

TEST_CASE("yoking by participant keeps a watcher on one walker across scenarios") {
  std::vector<Session> sessions = {walked(1, "a1", "lab", 10),       walked(2, "a2", "lab", 20),
                                   walked(3, "a2", "warehouse", 30), walked(4, "a1", "warehouse", 40)};
  YokeRequest b1 = video_link("b1", "lab");
  b1.by_participant = true;
  CHECK(chosen(sessions, b1) == 1);  // a1: the first walker, by their lab session's end
  sessions.push_back(watching(10, "b1", "lab", 1, SessionState::kFinished));
  // b1's next link is a1's warehouse session, though a2's ended first.
  b1.scenario = "warehouse";
  CHECK(chosen(sessions, b1) == 4);
  // b2 starts with warehouse: a1 is paired already (one viewer each), so a2.
  YokeRequest b2 = video_link("b2", "warehouse");
  b2.by_participant = true;
  CHECK(chosen(sessions, b2) == 3);
  sessions.push_back(watching(11, "b2", "warehouse", 3));
  b2.scenario = "lab";
  CHECK(chosen(sessions, b2) == 2);
  // b3: every walker has a paired watcher.
  YokeRequest b3 = video_link("b3", "lab");
  b3.by_participant = true;
  CHECK(chosen(sessions, b3) == 0);
  // A paired walker without a session of the scenario: none, not another walker's.
  YokeRequest b1_tutorial = video_link("b1", "tutorial");
  b1_tutorial.by_participant = true;
  CHECK(chosen(sessions, b1_tutorial) == 0);
}
