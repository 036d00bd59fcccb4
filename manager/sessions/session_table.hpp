// SPDX-License-Identifier: GPL-2.0-or-later
// The live sessions (starting, running, ending), found by token, uid, process or id. Pure: no I/O; the
// index keeps every session, this table only those that hold a slot.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sessions/session.hpp"

namespace rfbsim::manager {

class SessionTable {
 public:
  /// At most `capacity` live sessions.
  explicit SessionTable(int capacity) : capacity_(capacity) {}

  /// Whether every slot is taken.
  [[nodiscard]] bool full() const { return static_cast<int>(sessions_.size()) >= capacity_; }
  [[nodiscard]] int capacity() const { return capacity_; }
  [[nodiscard]] std::size_t size() const { return sessions_.size(); }

  /// Adds a live session (id, token and pid set). The table owns it; the reference stays valid until
  /// remove(). Throws std::logic_error when full, not live, or its id, token or uid is taken.
  Session& add(Session session);
  /// Removes the session with this id (when its process is gone).
  void remove(std::int64_t id);

  /// The live session with this token, uid, process id or row id; nullptr if none.
  Session* by_token(const std::string& token);
  Session* by_uid(const std::string& uid);
  Session* by_pid(pid_t pid);
  Session* by_id(std::int64_t id);

  /// Every live session, oldest first.
  [[nodiscard]] std::vector<Session*> all();

 private:
  int capacity_;
  std::map<std::int64_t, std::unique_ptr<Session>> sessions_;  // by id: ids grow, so oldest first
};

}  // namespace rfbsim::manager
