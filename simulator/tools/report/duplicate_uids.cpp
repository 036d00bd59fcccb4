// SPDX-License-Identifier: GPL-2.0-or-later
// Duplicate participants across hosts.
#include "duplicate_uids.hpp"

#include <map>
#include <set>

namespace rfbsim::report {

std::vector<DuplicateUid> flag_duplicate_uids(std::vector<SessionMetrics>& sessions) {
  // Each uid's hosts and sessions, in one pass; std::map keeps the uids sorted.
  std::map<std::string, std::set<std::string>> hosts;
  std::map<std::string, std::vector<std::size_t>> where;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    if (sessions[i].uid.empty()) continue;
    hosts[sessions[i].uid].insert(sessions[i].host);
    where[sessions[i].uid].push_back(i);
  }
  std::vector<DuplicateUid> out;
  for (const auto& [uid, seen] : hosts) {
    if (seen.size() < 2) continue;
    DuplicateUid duplicate{uid, {seen.begin(), seen.end()}, {}};
    for (const std::size_t i : where[uid]) {
      sessions[i].duplicate_uid = true;
      duplicate.folders.push_back(sessions[i].folder);
    }
    out.push_back(std::move(duplicate));
  }
  return out;
}

std::size_t host_count(const std::vector<SessionMetrics>& sessions) {
  std::set<std::string> hosts;
  for (const SessionMetrics& m : sessions) hosts.insert(m.host);
  return hosts.size();
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

std::string duplicate_uid_line(const DuplicateUid& duplicate, const std::vector<SessionMetrics>& sessions) {
  std::string line = "uid '" + duplicate.uid + "' has sessions on " + std::to_string(duplicate.hosts.size()) +
                     " hosts:";
  bool first = true;
  for (const SessionMetrics& m : sessions) {
    if (m.uid != duplicate.uid) continue;
    line += std::string(first ? " " : ", ") + m.host + " (" + m.folder + ")";
    first = false;
  }
  return line;
}

}  // namespace rfbsim::report
