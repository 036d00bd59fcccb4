// SPDX-License-Identifier: GPL-2.0-or-later
// A watcher's session (the video condition, docs/data.md "A watcher's session.json"): a folder whose session.json
// says `"condition": "video"` (or `"kind": "replay"`) and that holds no trajectories.csv or events.jsonl, since
// its participant only watched a replay of another's session. The tools recognise it by a lenient peek before
// any strict session reader sees the file (record/'s reader knows only interactive sessions), and the report
// reads it in full here.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace rfbsim::tools {

/// What a lenient look at a folder's session.json tells: which condition, and for a watcher whose session.
struct SessionKind {
  bool video = false;  ///< a watcher's session: `condition` is "video", or `kind` is "replay"
  /// A watcher's source: the manager's id of the session it watched; none when sim_rfb ran by hand (null),
  /// or the key is missing or not an integer.
  std::optional<std::int64_t> yoked_to;
  /// A `condition` that is neither "interactive" nor "video" (a file from a newer program); "" otherwise.
  std::string unknown_condition;
};

/// Peeks at `dir`/session.json. Never throws: a file that is missing, unreadable, oversized (over 4 MiB) or not
/// a JSON object reads as interactive, and the strict reader then says what is wrong with it. A file without
/// `condition` (written before the video condition existed) is interactive.
SessionKind peek_session_kind(const std::filesystem::path& dir);

/// A watcher's session.json is not what docs/data.md describes; the message names the file and the key.
class WatcherSessionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A watcher's session.json.
struct WatcherSession {
  std::string uid;                          ///< the watcher's participant id
  std::optional<std::int64_t> yoked_to;     ///< the source session's manager id (its manager.json `id`); none by hand
  std::string yoked_to_uid_hash;            ///< keyed hash of the source's uid (hex), never the uid; "" when null
  std::string scenario;                     ///< the source's scenario (session.json's, else replay_of's)
  std::string camera;                       ///< the view shown; "" when absent
  std::string source_started_at;            ///< replay_of.started_at: tells the source from a later one of its id
  std::string source_seed;                  ///< replay_of.seed, a decimal string; "" when absent
  std::optional<std::uint64_t> source_end_tick;  ///< replay_of.end_tick: the recording's length in ticks
  std::string started_at;                   ///< ISO 8601 UTC, when the watching began
  std::optional<std::string> ended_at;      ///< ISO 8601 UTC; none while watching (or after a crash)
  std::optional<std::uint64_t> end_tick;    ///< the recording's tick reached; none while watching
  std::optional<std::string> end_reason;    ///< watched, signal or error; none while watching
  std::optional<std::string> outcome;       ///< "watched" when the recording was shown to its end, else none
  std::int64_t viewers = 0;                 ///< viewer connections that came (each reconnect counts)
};

/// Parses a watcher's session.json `text`; `file` only names it in errors. Throws WatcherSessionError for a
/// file that is not a JSON object, lacks `uid`, `started_at` or `replay_of`, or holds a key of the wrong type.
WatcherSession parse_watcher_session(const std::string& text, const std::filesystem::path& file);

/// Reads `dir`/session.json as a watcher's. Throws WatcherSessionError (also for a missing, unreadable or
/// oversized file). It does not look for trajectories.csv or events.jsonl: a watcher's folder has none.
WatcherSession read_watcher_session(const std::filesystem::path& dir);

/// What a watcher's session is in words, for messages: "session 12" (its yoked_to), or "a recording" when
/// sim_rfb was run by hand (yoked_to null).
std::string watched_source(const std::optional<std::int64_t>& yoked_to);

}  // namespace rfbsim::tools
