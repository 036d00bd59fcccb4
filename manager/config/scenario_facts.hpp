// SPDX-License-Identifier: GPL-2.0-or-later
// The scenario facts the manager checks links and durations against (spawn points, robot, task clock). They are
// read by the simulator's own scenario code (simulator/scenario/scenario_facts.hpp, C++17 for the manager), so
// that the scenario format has one reader's home; these names keep the manager's rooms speaking of them as theirs.
#pragma once

#include "scenario/scenario_facts.hpp"

namespace rfbsim::manager {

using sim::load_scenario_facts;
using sim::parse_scenario_facts;
using sim::ScenarioFacts;

}  // namespace rfbsim::manager
