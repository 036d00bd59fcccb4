// SPDX-License-Identifier: GPL-2.0-or-later
// The manager's one shape of a log line about a session, "session ID (uid UID): text", shared by the supervisor
// and the after-session copier so that a researcher can grep one session's whole story.
#pragma once

#include <cstdint>
#include <string>

#include "rfbsim/log.hpp"

namespace rfbsim::manager {

inline void log_about_session(std::int64_t id, const std::string& uid, const std::string& text) {
  rfbsim::log::info("manager", "session %lld (uid %s): %s", static_cast<long long>(id), uid.c_str(), text.c_str());
}

}  // namespace rfbsim::manager
