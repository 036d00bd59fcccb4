// SPDX-License-Identifier: GPL-2.0-or-later
// Participation: manager.json applied, and the sessions without a participant named.
#include "participation.hpp"

namespace rfbsim::report {

void add_manager_record(const ManagerRecord& record, SessionMetrics& metrics) {
  metrics.has_manager_record = true;
  metrics.manager_state = record.state;
  metrics.manager_detail = record.detail;
  metrics.link_spent = record.spent_after.has_value();
  metrics.link_spent_after = record.spent_after;
  if (record.id) metrics.session_id = record.id;  // the manager's own word over the folder's name
  if (metrics.watcher && !metrics.watcher->yoked_to) metrics.watcher->yoked_to = record.yoked_to;
  // session.json's reason is sim_rfb's own, with its dropped bytes; the manager's is the same failure as told
  // on the ready pipe, and the only word of it when session.json could not take the reason.
  if (metrics.data_incomplete.empty() && record.data_incomplete) {
    metrics.data_incomplete = record.data_incomplete->empty() ? "unknown" : *record.data_incomplete;
  }
}

std::string exclusion_reason(const SessionMetrics& m) {
  if (!m.has_manager_record || m.link_spent) return "";
  if (m.manager_state == "abandoned") return "abandoned: no picture ever reached a participant's browser";
  const bool live = m.manager_state == "starting" || m.manager_state == "running" || m.manager_state == "ending";
  return live ? "still " + m.manager_state + ", and no picture has reached a participant's browser yet"
              : m.manager_state + " before any picture reached a participant's browser";
}

bool in_statistics(const SessionMetrics& m) { return !m.video() && exclusion_reason(m).empty(); }

std::vector<Exclusion> exclusions(const std::vector<SessionMetrics>& sessions) {
  std::vector<Exclusion> out;
  for (const SessionMetrics& m : sessions) {
    if (m.video()) continue;  // counted apart, whatever became of them
    const std::string reason = exclusion_reason(m);
    if (reason.empty()) continue;
    bool counted = false;
    for (Exclusion& e : out) {
      if (e.reason == reason) {
        ++e.sessions;
        counted = true;
      }
    }
    if (!counted) out.push_back({reason, 1});
  }
  return out;
}

}  // namespace rfbsim::report
