// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <iterator>
#include <optional>
#include <string>

#include "sessions/session.hpp"

using rfbsim::manager::admit;
using rfbsim::manager::Admission;
using rfbsim::manager::begin_ending;
using rfbsim::manager::counts_as_completed;
using rfbsim::manager::describe_wait_status;
using rfbsim::manager::is_live;
using rfbsim::manager::kAllStates;
using rfbsim::manager::Session;
using rfbsim::manager::SessionState;
using rfbsim::manager::state_after_exit;
using rfbsim::manager::WallTime;
using rfbsim::manager::state_from_name;
using rfbsim::manager::state_name;

namespace {

// The wait status of a child that exits with `code`, as waitpid reports it.
int exited(int code) { return W_EXITCODE(code, 0); }

// The wait status of a child that a signal killed, from a real child: the encoding is the kernel's.
int killed_by(int signal) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(signal, SIG_DFL);
    ::raise(signal);
    ::_exit(99);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

// A session in `state` whose participant has seen it (its link is spent), unless said otherwise.
Session in_state(SessionState state, bool spent = true) {
  Session session;
  session.state = state;
  if (spent) session.spent_at = WallTime{} + std::chrono::seconds(1);
  return session;
}

}  // namespace

TEST_CASE("state names round-trip for every state") {
  CHECK(std::size(kAllStates) == 12);
  for (const SessionState state : kAllStates) {
    INFO(state_name(state));
    CHECK(state_from_name(state_name(state)) == state);
  }
  CHECK(std::string(state_name(SessionState::kStarting)) == "starting");
  CHECK(std::string(state_name(SessionState::kRunning)) == "running");
  CHECK(std::string(state_name(SessionState::kEnding)) == "ending");
  CHECK(std::string(state_name(SessionState::kFinished)) == "finished");
  CHECK(std::string(state_name(SessionState::kExpired)) == "expired");
  CHECK(std::string(state_name(SessionState::kIdle)) == "idle");
  CHECK(std::string(state_name(SessionState::kEnded)) == "ended");
  CHECK(std::string(state_name(SessionState::kShutdown)) == "shutdown");
  CHECK(std::string(state_name(SessionState::kCrashed)) == "crashed");
  CHECK(std::string(state_name(SessionState::kFailed)) == "failed");
  CHECK(std::string(state_name(SessionState::kInterrupted)) == "interrupted");
}

TEST_CASE("unknown state names give nothing") {
  CHECK_FALSE(state_from_name(""));
  CHECK_FALSE(state_from_name("Running"));
  CHECK_FALSE(state_from_name("running "));
  CHECK_FALSE(state_from_name("unknown"));
}

TEST_CASE("starting, running and ending are live and nothing else is") {
  int live = 0;
  for (const SessionState state : kAllStates) live += is_live(state) ? 1 : 0;
  CHECK(live == 3);
  CHECK(is_live(SessionState::kStarting));
  CHECK(is_live(SessionState::kRunning));
  CHECK(is_live(SessionState::kEnding));
}

TEST_CASE("finished, expired, idle and ended count as completed and nothing else does") {
  int completed = 0;
  for (const SessionState state : kAllStates) completed += counts_as_completed(state) ? 1 : 0;
  CHECK(completed == 4);
  CHECK(counts_as_completed(SessionState::kFinished));
  CHECK(counts_as_completed(SessionState::kExpired));
  CHECK(counts_as_completed(SessionState::kIdle));
  CHECK(counts_as_completed(SessionState::kEnded));
  CHECK_FALSE(counts_as_completed(SessionState::kCrashed));
  CHECK_FALSE(counts_as_completed(SessionState::kFailed));
  CHECK_FALSE(counts_as_completed(SessionState::kInterrupted));
  CHECK_FALSE(counts_as_completed(SessionState::kShutdown));
  CHECK_FALSE(counts_as_completed(SessionState::kAbandoned));
}

TEST_CASE("begin_ending moves a starting or running session to ending") {
  for (const SessionState from : {SessionState::kStarting, SessionState::kRunning}) {
    Session session = in_state(from);
    REQUIRE(begin_ending(session, SessionState::kExpired, "maximum duration reached"));
    CHECK(session.state == SessionState::kEnding);
    CHECK(session.end_as == SessionState::kExpired);
    CHECK(session.detail == "maximum duration reached");
  }
}

TEST_CASE("begin_ending changes nothing for a session that is not starting or running") {
  for (const SessionState from : kAllStates) {
    if (from == SessionState::kStarting || from == SessionState::kRunning) continue;
    INFO(state_name(from));
    Session session = in_state(from);
    session.end_as = SessionState::kIdle;
    session.detail = "before";
    CHECK_FALSE(begin_ending(session, SessionState::kEnded, "after"));
    CHECK(session.state == from);
    CHECK(session.end_as == SessionState::kIdle);
    CHECK(session.detail == "before");
  }
}

TEST_CASE("the state after the process exits") {
  SECTION("running, exit 0: finished") {
    CHECK(state_after_exit(in_state(SessionState::kRunning), exited(0)) == SessionState::kFinished);
  }
  SECTION("running, another exit status: crashed") {
    CHECK(state_after_exit(in_state(SessionState::kRunning), exited(1)) == SessionState::kCrashed);
    CHECK(state_after_exit(in_state(SessionState::kRunning), exited(255)) == SessionState::kCrashed);
  }
  SECTION("running, killed by a signal: crashed") {
    CHECK(state_after_exit(in_state(SessionState::kRunning), killed_by(SIGKILL)) == SessionState::kCrashed);
    CHECK(state_after_exit(in_state(SessionState::kRunning), killed_by(SIGHUP)) == SessionState::kCrashed);
  }
  SECTION("starting: failed, however it exits") {
    CHECK(state_after_exit(in_state(SessionState::kStarting), exited(0)) == SessionState::kFailed);
    CHECK(state_after_exit(in_state(SessionState::kStarting), exited(2)) == SessionState::kFailed);
    CHECK(state_after_exit(in_state(SessionState::kStarting), killed_by(SIGTERM)) == SessionState::kFailed);
  }
  SECTION("ending: the state it was ending as, however it exits") {
    Session session = in_state(SessionState::kRunning);
    REQUIRE(begin_ending(session, SessionState::kIdle, "idle"));
    CHECK(state_after_exit(session, exited(0)) == SessionState::kIdle);
    CHECK(state_after_exit(session, exited(3)) == SessionState::kIdle);
    CHECK(state_after_exit(session, killed_by(SIGKILL)) == SessionState::kIdle);
  }
  SECTION("a session whose link was never spent is abandoned where it would have counted as completed") {
    CHECK(state_after_exit(in_state(SessionState::kRunning, false), exited(0)) == SessionState::kAbandoned);
    Session idle = in_state(SessionState::kRunning, false);
    REQUIRE(begin_ending(idle, SessionState::kIdle, "idle"));
    CHECK(state_after_exit(idle, exited(0)) == SessionState::kAbandoned);
    Session expired = in_state(SessionState::kStarting, false);
    REQUIRE(begin_ending(expired, SessionState::kExpired, "expired"));
    CHECK(state_after_exit(expired, killed_by(SIGKILL)) == SessionState::kAbandoned);
    // Crashes, failures and shutdowns keep their own state: they say what went wrong.
    CHECK(state_after_exit(in_state(SessionState::kRunning, false), exited(1)) == SessionState::kCrashed);
    CHECK(state_after_exit(in_state(SessionState::kStarting, false), exited(0)) == SessionState::kFailed);
    Session shutdown = in_state(SessionState::kRunning, false);
    REQUIRE(begin_ending(shutdown, SessionState::kShutdown, "stop"));
    CHECK(state_after_exit(shutdown, exited(0)) == SessionState::kShutdown);
  }
  SECTION("already final: unchanged") {
    CHECK(state_after_exit(in_state(SessionState::kExpired), exited(1)) == SessionState::kExpired);
    CHECK(state_after_exit(in_state(SessionState::kCrashed), exited(0)) == SessionState::kCrashed);
  }
}

TEST_CASE("wait statuses in words") {
  CHECK(describe_wait_status(exited(0)) == "exit 0");
  CHECK(describe_wait_status(exited(3)) == "exit 3");
  CHECK(describe_wait_status(exited(255)) == "exit 255");
  CHECK(describe_wait_status(killed_by(SIGKILL)) == "signal 9");
  CHECK(describe_wait_status(killed_by(SIGTERM)) == "signal 15");
  CHECK(describe_wait_status(SIGKILL) == "signal 9");  // the encoding: the signal in the low bits
  CHECK(describe_wait_status(W_STOPCODE(SIGSTOP)) == "status " + std::to_string(W_STOPCODE(SIGSTOP)));
}

TEST_CASE("the admission rule") {
  using S = SessionState;
  const std::optional<S> none;
  SECTION("a live session is joined whatever else holds") {
    CHECK(admit(true, none, false, false) == Admission::kJoinLive);
    CHECK(admit(true, none, false, true) == Admission::kJoinLive);
    CHECK(admit(true, S::kFinished, false, true) == Admission::kJoinLive);
    CHECK(admit(true, S::kFinished, true, false) == Admission::kJoinLive);
  }
  SECTION("a completed last session refuses unless repeats are allowed") {
    for (const S last : {S::kFinished, S::kExpired, S::kIdle, S::kEnded}) {
      INFO(state_name(last));
      CHECK(admit(false, last, false, false) == Admission::kAlreadyCompleted);
      CHECK(admit(false, last, false, true) == Admission::kAlreadyCompleted);  // before busy
      CHECK(admit(false, last, true, false) == Admission::kStartNew);
      CHECK(admit(false, last, true, true) == Admission::kBusy);
    }
  }
  SECTION("a last session that was not the participant's doing starts afresh") {
    for (const S last : {S::kCrashed, S::kFailed, S::kInterrupted, S::kShutdown}) {
      INFO(state_name(last));
      CHECK(admit(false, last, false, false) == Admission::kStartNew);
      CHECK(admit(false, last, false, true) == Admission::kBusy);
    }
  }
  SECTION("a new uid") {
    CHECK(admit(false, none, false, false) == Admission::kStartNew);
    CHECK(admit(false, none, true, false) == Admission::kStartNew);
    CHECK(admit(false, none, false, true) == Admission::kBusy);
  }
}
