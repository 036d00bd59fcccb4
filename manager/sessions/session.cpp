// SPDX-License-Identifier: GPL-2.0-or-later
// A session's life cycle.
#include "sessions/session.hpp"

#include <sys/wait.h>

namespace rfbsim::manager {

const char* state_name(SessionState state) {
  switch (state) {
    case SessionState::kStarting: return "starting";
    case SessionState::kRunning: return "running";
    case SessionState::kEnding: return "ending";
    case SessionState::kFinished: return "finished";
    case SessionState::kExpired: return "expired";
    case SessionState::kIdle: return "idle";
    case SessionState::kEnded: return "ended";
    case SessionState::kShutdown: return "shutdown";
    case SessionState::kCrashed: return "crashed";
    case SessionState::kFailed: return "failed";
    case SessionState::kInterrupted: return "interrupted";
    case SessionState::kAbandoned: return "abandoned";
  }
  return "unknown";
}

std::optional<SessionState> state_from_name(std::string_view name) {
  for (const SessionState state : kAllStates) {
    if (name == state_name(state)) return state;
  }
  return std::nullopt;
}

bool is_live(SessionState state) {
  return state == SessionState::kStarting || state == SessionState::kRunning || state == SessionState::kEnding;
}

bool counts_as_completed(SessionState state) {
  return state == SessionState::kFinished || state == SessionState::kExpired || state == SessionState::kIdle ||
         state == SessionState::kEnded;
}

SessionState coming_state(const Session& session) {
  return session.state == SessionState::kEnding ? session.end_as : session.state;
}

bool begin_ending(Session& session, SessionState end_as, std::string detail) {
  if (session.state != SessionState::kStarting && session.state != SessionState::kRunning) return false;
  session.end_as = end_as;
  session.state = SessionState::kEnding;
  session.detail = std::move(detail);
  return true;
}

namespace {

SessionState exit_state(const Session& session, int wait_status) {
  switch (session.state) {
    case SessionState::kEnding: return session.end_as;
    case SessionState::kStarting: return SessionState::kFailed;
    case SessionState::kRunning:
      return WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0 ? SessionState::kFinished
                                                                      : SessionState::kCrashed;
    default: return session.state;  // already final: nothing changes
  }
}

}  // namespace

SessionState state_after_exit(const Session& session, int wait_status) {
  const SessionState state = exit_state(session, wait_status);
  // Nobody saw it: a preview, a blocked WebSocket or a tab closed early must not use up the participant.
  if (is_live(session.state) && counts_as_completed(state) && !session.spent_at) return SessionState::kAbandoned;
  return state;
}

std::string describe_wait_status(int wait_status) {
  if (WIFEXITED(wait_status)) return "exit " + std::to_string(WEXITSTATUS(wait_status));
  if (WIFSIGNALED(wait_status)) return "signal " + std::to_string(WTERMSIG(wait_status));
  return "status " + std::to_string(wait_status);
}

Admission admit(bool has_live, std::optional<SessionState> last_state, bool allow_repeat, bool full) {
  if (has_live) return Admission::kJoinLive;
  if (!allow_repeat && last_state && counts_as_completed(*last_state)) return Admission::kAlreadyCompleted;
  if (full) return Admission::kBusy;
  return Admission::kStartNew;
}

}  // namespace rfbsim::manager
