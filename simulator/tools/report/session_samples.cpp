// SPDX-License-Identifier: GPL-2.0-or-later
// SampledSession: rows gathered by tick, partial samples left out.
#include "session_samples.hpp"

#include <map>

namespace rfbsim::report {

namespace {

AgentState state_of(const sim::TrajectoryRow& row) { return {row.x, row.y, row.yaw, row.vx, row.vy}; }

}  // namespace

SampledSession assemble_samples(const sim::SessionLog& log) {
  SampledSession out;
  out.sample_interval = 1.0 / log.meta.trajectory_hz;
  std::map<int, std::size_t> person_slot;  // person id -> index in people
  for (const sim::SessionAgent& agent : log.meta.agents) {
    switch (agent.kind) {
      case sim::AgentKind::Avatar: out.avatar_radius = agent.radius; break;
      case sim::AgentKind::Robot:
        out.has_robot = true;
        out.robot_radius = agent.radius;
        break;
      case sim::AgentKind::Person:
        person_slot[agent.id] = out.person_ids.size();
        out.person_ids.push_back(agent.id);
        out.person_radii.push_back(agent.radius);
        break;
    }
  }
  const std::size_t agents = 1 + (out.has_robot ? 1 : 0) + out.person_ids.size();

  // The reader guarantees ticks never go backwards, so each tick's rows are one run of the file.
  const std::vector<sim::TrajectoryRow>& rows = log.trajectory;
  for (std::size_t begin = 0; begin < rows.size();) {
    std::size_t end = begin;
    while (end < rows.size() && rows[end].tick == rows[begin].tick) ++end;

    Sample sample;
    sample.tick = rows[begin].tick;
    sample.time = rows[begin].time;
    sample.people.resize(out.person_ids.size());
    std::vector<bool> seen(agents, false);
    bool whole = end - begin == agents;
    for (std::size_t i = begin; i < end && whole; ++i) {
      const sim::TrajectoryRow& row = rows[i];
      std::size_t slot = 0;  // avatar 0, robot 1, then people
      if (row.kind == sim::AgentKind::Robot) slot = 1;
      if (row.kind == sim::AgentKind::Person) slot = (out.has_robot ? 2 : 1) + person_slot.at(row.id);
      if (seen[slot]) whole = false;
      seen[slot] = true;
      switch (row.kind) {
        case sim::AgentKind::Avatar: sample.avatar = state_of(row); break;
        case sim::AgentKind::Robot: sample.robot = state_of(row); break;
        case sim::AgentKind::Person: sample.people[person_slot.at(row.id)] = state_of(row); break;
      }
    }
    if (whole) {
      out.samples.push_back(std::move(sample));
    } else {
      ++out.partial_samples;
    }
    begin = end;
  }
  return out;
}

}  // namespace rfbsim::report
