// SPDX-License-Identifier: GPL-2.0-or-later
// The live sessions. A handful at a time (tens at most), so lookups walk the map.
#include "sessions/session_table.hpp"

#include <stdexcept>

namespace rfbsim::manager {

Session& SessionTable::add(Session session) {
  if (full()) throw std::logic_error("session table: no free slot");
  if (!is_live(session.state)) throw std::logic_error("session table: only live sessions are kept");
  if (by_id(session.id) || by_token(session.token) || by_uid(session.uid)) {
    throw std::logic_error("session table: id, token or uid already live");
  }
  auto owned = std::make_unique<Session>(std::move(session));
  Session& ref = *owned;
  sessions_.emplace(ref.id, std::move(owned));
  return ref;
}

void SessionTable::remove(std::int64_t id) { sessions_.erase(id); }

Session* SessionTable::by_token(const std::string& token) {
  for (auto& [id, session] : sessions_) {
    if (session->token == token) return session.get();
  }
  return nullptr;
}

Session* SessionTable::by_uid(const std::string& uid) {
  for (auto& [id, session] : sessions_) {
    if (session->uid == uid) return session.get();
  }
  return nullptr;
}

Session* SessionTable::by_pid(pid_t pid) {
  for (auto& [id, session] : sessions_) {
    if (session->pid == pid) return session.get();
  }
  return nullptr;
}

Session* SessionTable::by_id(std::int64_t id) {
  const auto it = sessions_.find(id);
  return it == sessions_.end() ? nullptr : it->second.get();
}

std::vector<Session*> SessionTable::all() {
  std::vector<Session*> out;
  for (auto& [id, session] : sessions_) out.push_back(session.get());
  return out;
}

}  // namespace rfbsim::manager
