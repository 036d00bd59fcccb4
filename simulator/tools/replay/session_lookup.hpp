// SPDX-License-Identifier: GPL-2.0-or-later
// lookup_session: the one session folder that `sim_replay --data-dir DIR... --uid UID | --session ID` names,
// found across several hosts' data folders or the shared store (tools::catalog_sessions: a copy of a session
// found twice is one session). None, or more than one, is an error that lists what was found.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "session_catalog.hpp"

namespace rfbsim::replay {

/// Which session to find.
struct SessionQuery {
  std::optional<std::string> uid;      ///< session.json's uid equals this
  std::optional<std::string> session;  ///< the folder's name equals this, or (all digits) its "<id>-" prefix
  std::optional<std::string> host;     ///< and the session's host (FoundSession::host) equals this
};

/// The session found, or why there is not exactly one.
struct LookupResult {
  std::optional<tools::FoundSession> found;  ///< set when exactly one session matched
  std::string error;                         ///< otherwise: what was asked, where, and any candidates
};

/// Finds the session `query` names under `data_dirs`. A data folder that does not exist is an error;
/// a session.json that cannot be read does not match a uid (the error then says how many there were).
LookupResult lookup_session(const std::vector<std::filesystem::path>& data_dirs, const SessionQuery& query);

}  // namespace rfbsim::replay
