// SPDX-License-Identifier: GPL-2.0-or-later
// ManagerRecord: sim_manager's manager.json beside a session's data (how the session ended, whether its link
// was spent), read for the report. The file is optional (sessions run by hand have none) and comes from
// another program: a broken one is a warning naming the file, and the session is reported without it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace rfbsim::report {

/// manager.json is there but not what docs/report.md describes; the message names the file and what is wrong.
class ManagerRecordError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What sim_report uses of manager.json.
struct ManagerRecord {
  std::string uid;     ///< the participant id the manager started the session for
  std::string state;   ///< starting, running, ..., abandoned (manager_states())
  std::string detail;  ///< the manager's words on the state; may be empty
  /// s from created_at (the manager creating the session) to spent_at (its first picture reaching the
  /// participant's browser); none while the link is unspent.
  std::optional<double> spent_after;
  std::optional<std::string> data_incomplete;  ///< the reason sim_rfb gave the manager; none when complete
  /// The host id of the manager that ran the session; none in files from managers that did not record it.
  std::optional<std::string> host;
  /// The session's id on its host (the `<id>` of its `<id>-<uid>` folder); none in files without it.
  std::optional<std::int64_t> id;
  /// "interactive" or "video" (a watcher of another session's replay); interactive in older files.
  std::string condition = "interactive";
  std::optional<std::int64_t> yoked_to;  ///< a watcher's source session id on the same host; none otherwise
  std::optional<std::string> yoked_to_uid_hash;  ///< keyed hash of the source's uid (hex); none otherwise
};

/// Every state manager.json may hold, space-separated in the manager's order.
const char* manager_states();

/// Parses manager.json's `text`; `file` only names it in errors. Throws ManagerRecordError.
ManagerRecord parse_manager_record(const std::string& text, const std::filesystem::path& file);

/// Reads `dir`/manager.json: none when the folder has no such file; throws ManagerRecordError when it is
/// there but unreadable, oversized (over 64 KiB) or broken.
std::optional<ManagerRecord> read_manager_record(const std::filesystem::path& dir);

/// Milliseconds since 1970 of an ISO 8601 UTC time as the manager writes it ("2026-11-25T10:00:00.300Z";
/// the fraction is optional, up to nine digits); none for anything else, an impossible date included.
std::optional<long long> parse_utc_millis(const std::string& text);

}  // namespace rfbsim::report
