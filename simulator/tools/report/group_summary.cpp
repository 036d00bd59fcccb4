// SPDX-License-Identifier: GPL-2.0-or-later
// GroupSummary: rates and statistics per group of sessions.
#include "group_summary.hpp"

#include <algorithm>
#include <map>

#include "participation.hpp"
#include "report_columns.hpp"

namespace rfbsim::report {

namespace {

GroupSummary summarize_group(const std::vector<const SessionMetrics*>& members) {
  // Only the interactive sessions someone took part in; the others are counted, not measured.
  std::vector<const SessionMetrics*> group;
  GroupSummary out;
  for (const SessionMetrics* m : members) {
    if (m->video()) {
      ++out.video;
    } else if (in_statistics(*m)) {
      group.push_back(m);
    } else {
      ++out.excluded;
    }
  }
  out.sessions = group.size();
  for (const Rate& rate : summary_rates()) {
    const auto yes = std::count_if(group.begin(), group.end(), [&](const SessionMetrics* m) { return rate.holds(*m); });
    const double n = static_cast<double>(group.size());
    out.rate_percent.push_back(group.empty() ? 0.0 : 100.0 * static_cast<double>(yes) / n);
  }
  for (const std::string& name : summarized_columns()) {
    const Column& column = session_column(name);
    std::vector<double> values;
    for (const SessionMetrics* m : group) {
      if (const auto v = numeric_value(column.value(*m))) values.push_back(*v);
    }
    out.statistics.push_back(statistic_of(std::move(values)));
  }
  return out;
}

}  // namespace

const std::vector<Rate>& summary_rates() {
  using M = SessionMetrics;
  // The paper's figures (SEAN-EP, 372 sessions) beside the rates it reported; the gap rates are ours.
  static const std::vector<Rate> rates = {
      {"timed_out", "timed out", [](const M& m) { return m.timed_out; }, 6.18},
      {"completed", "completed", [](const M& m) { return m.completed; }, std::nullopt},
      {"never_moved", "never moved", [](const M& m) { return m.never_moved; }, 2.15},
      {"found_robot", "found the robot", [](const M& m) { return m.found_robot; }, std::nullopt},
      {"robot_within_0_45", "robot within 0.45 m (centres)", [](const M& m) { return m.robot_within_0_45; }, 52.4},
      {"robot_within_1_2", "robot within 1.2 m (centres)", [](const M& m) { return m.robot_within_1_2; }, 84.9},
      {"robot_gap_within_0_45", "robot within 0.45 m (surfaces)", [](const M& m) { return m.robot_gap_within_0_45; },
       std::nullopt},
      {"robot_gap_within_1_2", "robot within 1.2 m (surfaces)", [](const M& m) { return m.robot_gap_within_1_2; },
       std::nullopt},
      // Issue 19's target for the robot's own conduct (bench_nav: "robot-caused intimate-space intrusions").
      {"robot_caused_intimate", "robot itself came within 0.45 m",
       [](const M& m) { return m.social && m.social->robot_intimate_intrusions > 0; }, std::nullopt},
      {"avatar_pushed_robot", "avatar pushed the robot", [](const M& m) { return m.avatar_pushed_robot; },
       std::nullopt},
      {"avatar_person_collision", "avatar-person collision", [](const M& m) { return m.avatar_person_collisions > 0; },
       std::nullopt},
  };
  return rates;
}

const std::vector<std::string>& summarized_columns() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Column& c : session_columns()) {
      if (c.summarized) out.push_back(c.name);
    }
    return out;
  }();
  return names;
}

Statistic statistic_of(std::vector<double> values) {
  Statistic out;
  out.n = values.size();
  if (values.empty()) return out;
  double sum = 0.0;
  for (const double v : values) sum += v;
  out.mean = sum / static_cast<double>(values.size());
  std::sort(values.begin(), values.end());
  const std::size_t mid = values.size() / 2;
  out.median = values.size() % 2 == 1 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
  return out;
}

std::vector<GroupSummary> summarize(const std::vector<SessionMetrics>& sessions) {
  std::vector<const SessionMetrics*> everyone;
  std::map<std::string, std::vector<const SessionMetrics*>> by_scenario;
  for (const SessionMetrics& m : sessions) {
    everyone.push_back(&m);
    by_scenario[m.scenario].push_back(&m);
  }
  std::vector<GroupSummary> out;
  out.push_back(summarize_group(everyone));
  out.back().all = true;
  for (const auto& [scenario, group] : by_scenario) {
    out.push_back(summarize_group(group));
    out.back().scenario = scenario;
  }
  return out;
}

}  // namespace rfbsim::report
