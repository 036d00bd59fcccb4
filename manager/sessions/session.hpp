// SPDX-License-Identifier: GPL-2.0-or-later
// One participant's session as the manager keeps it, and the rules of its life cycle. Pure: no I/O.
//
//   starting --ready--> running --exit 0--> finished
//      |                  |  \--other exit--> crashed
//      |                  \--expiry / idle / admin / shutdown--> ending --exit--> expired | idle | ended | shutdown
//      \--exit or start timeout--> failed
// A session found live in the index by a manager that restarted is marked interrupted. A session that would
// end as finished, expired, idle or ended without its link ever being spent (no picture ever reached a
// participant's browser: a link preview, a blocked WebSocket, a tab closed early) ends as abandoned instead,
// and its uid may start again.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "contract/stream_line.hpp"

namespace rfbsim::manager {

/// sim_rfb's latest stream line, as the contract parses it (contract/stream_line.hpp).
using contract::StreamReport;

enum class SessionState {
  kStarting,     ///< process started, not yet ready
  kRunning,      ///< ready: its port takes connections
  kEnding,       ///< told to stop (SIGTERM), not yet gone
  kFinished,     ///< the program ended by itself with status 0
  kExpired,      ///< ended at the maximum duration
  kIdle,         ///< ended after the idle timeout (no browser connected)
  kEnded,        ///< ended by an administrator
  kShutdown,     ///< ended because the manager stopped
  kCrashed,      ///< the program died on its own (signal or non-zero status) while running
  kFailed,       ///< never became ready (bad parameters, start timeout, cannot run)
  kInterrupted,  ///< the manager died while it ran; found and ended by the next manager
  kAbandoned,    ///< ran its course without a picture ever reaching a participant: the link is not spent
};

/// Every state, for metrics that list them all.
inline constexpr SessionState kAllStates[] = {
    SessionState::kStarting, SessionState::kRunning, SessionState::kEnding,  SessionState::kFinished,
    SessionState::kExpired,  SessionState::kIdle,    SessionState::kEnded,   SessionState::kShutdown,
    SessionState::kCrashed,  SessionState::kFailed,  SessionState::kInterrupted, SessionState::kAbandoned};

/// "starting", "running", ... as stored in the index and shown in metrics.
const char* state_name(SessionState state);
std::optional<SessionState> state_from_name(std::string_view name);

/// Starting, running or ending: the session holds a slot and a process.
bool is_live(SessionState state);

/// A session that ran its course (finished, expired, idle, ended): its uid may not start again unless
/// repeats are allowed. Crashed, failed, interrupted, shutdown and abandoned sessions were not the
/// participant's doing (or never had them), so the same link may start afresh.
bool counts_as_completed(SessionState state);

using WallTime = std::chrono::system_clock::time_point;

/// One session: the model (who, what) and where it stands.
struct Session {
  std::int64_t id = 0;          ///< index row id, from 1
  std::string uid;              ///< participant id (validated identifier)
  std::string token;            ///< 32 hex digits: 128 random bits, the capability to reach the session
  std::string scenario;
  std::string params_json;      ///< the link's parameters (sig left out), as a JSON object
  std::uint64_t seed = 0;
  std::string host_id;
  SessionState state = SessionState::kStarting;
  SessionState end_as = SessionState::kEnded;  ///< while ending: the state it gets when the process is gone
  std::string detail;           ///< why it ended, in words ("exit status 2: ...", "killed by signal 9")
  std::string exit_status;      ///< "exit 0", "signal 9", "" while running
  pid_t pid = -1;               ///< also the process group id (the session leads its own group)
  std::int64_t process_start = 0;  ///< the process's start time in clock ticks (/proc), to recognise it later
  int port = 0;                 ///< loopback port the session serves RFB on, once known (0 with a unix socket)
  std::string unix_socket;      ///< or the unix socket it serves RFB on (sim_rfb sessions); memory only
  std::string data_path;        ///< the session's folder
  std::string code_success;     ///< the link's t1 (shown and sent to the survey on success); may be empty
  std::string code_timeout;     ///< the link's t2 (on timeout); may be empty
  std::string outcome;          ///< the task's outcome as the simulator reported it: "", completed, timeout
  WallTime created{};           ///< /start accepted
  std::optional<WallTime> ready_at;  ///< the program reported ready
  std::optional<WallTime> ended_at;  ///< the process was gone
  /// When the link was spent: the session's first picture was delivered to a participant's browser. Unset
  /// until then; a session that ends unspent is abandoned.
  std::optional<WallTime> spent_at;
  /// Why the session's recorded data is incomplete, as the program reported it (a full disk...); "" = complete.
  std::string data_incomplete;
  /// The after-session copy of the session's folder (after_session_command): "" none configured, "pending",
  /// "done" or "failed"; its tries so far; its last failure in words ("" when done).
  std::string copy_state;
  int copy_attempts = 0;
  std::string copy_error;
  /// The client address /start came from, for the per-address limit on unspent sessions. Kept in memory only:
  /// participants' addresses are not part of the study's record.
  std::string start_address;
  /// The keyed hash of the participant's whole address that opened /start (the peer, or the participant a
  /// trusted proxy names; not its /64), as sim_rfb writes it in events.jsonl (record/digest.hpp,
  /// hash_address); "" when unknown. The index and manager.json keep this, never the address.
  std::string address_hash;
  /// The session's topics under the lab's ROS when it dials out to the lab's rosbridge_server
  /// ("/rfbsim/s_12"; "" = no ROS), and who drove its robot ("builtin", "external"; "" = no robot known):
  /// launch_plan's session_ros. For the researcher only: never on a participant's page.
  std::string ros_namespace;
  std::string robot_control;
  /// The study's condition (issue 33): "interactive" (walked) or "video" (watched a replay of `yoked_to`, the
  /// id of an interactive session of this host, whose uid's keyed hash is `yoked_to_uid_hash`; never its uid).
  std::string condition = "interactive";
  std::int64_t yoked_to = 0;
  std::string yoked_to_uid_hash;
  /// Interactive sessions: how many video sessions hold their place as its watchers (the index counts them as
  /// it writes a watcher's row; read from the index, never written from here).
  int watchers = 0;
  /// The participant's stream as sim_rfb last reported it while someone watched; unset before the first report,
  /// when nobody watches, and for sessions read from the index (it is not stored there).
  std::optional<StreamReport> stream;
};

/// The state a session has, or while ending the one it will get: what a browser or page is told.
SessionState coming_state(const Session& session);

/// Moves a starting or running session to ending, to become `end_as` once its process is gone.
/// Returns false (and changes nothing) if it is not starting or running.
bool begin_ending(Session& session, SessionState end_as, std::string detail);

/// The state a live session takes when its process exits with `wait_status` (as from waitpid): abandoned
/// instead of a completed state when its link was never spent.
SessionState state_after_exit(const Session& session, int wait_status);

/// "exit 3" or "signal 9" for a wait status.
std::string describe_wait_status(int wait_status);

/// What admitting a /start for a uid comes to.
enum class Admission {
  kJoinLive,          ///< the uid has a live session: back to it
  kAlreadyCompleted,  ///< the uid's last session ran its course and repeats are not allowed
  kBusy,              ///< no free slot
  kStartNew,          ///< start a session
};

/// The admission rule. `has_live`: the uid has a live session; `last_state`: the state of its latest
/// session that is not live, if any; `full`: every slot taken.
Admission admit(bool has_live, std::optional<SessionState> last_state, bool allow_repeat, bool full);

}  // namespace rfbsim::manager
