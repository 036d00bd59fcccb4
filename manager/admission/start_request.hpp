// SPDX-License-Identifier: GPL-2.0-or-later
// The parameters of a /start link, each validated strictly: uid, scenario, seed and the scenario
// overrides a study may set per participant; a spawn point's name is checked against the scenario's own
// (ScenarioFacts), so that a link naming one it lacks is refused here rather than starting a session that
// fails. Pure: no I/O.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "config/scenario_facts.hpp"
#include "contract/validators.hpp"
#include "http/query.hpp"

namespace rfbsim::manager {

/// What a participant's link asks for, all of it valid.
struct StartRequest {
  std::string uid;                    ///< participant id: letters, digits, - and _, 1..64
  std::string scenario;               ///< a name from the allowed list; "" where the list is empty
  std::optional<std::uint64_t> seed;  ///< unset = the manager draws one (and records it)
  /// Scenario overrides as (link parameter, value), in the order of kOverrideParams; e.g.
  /// ("avatar_start", "1.5,-2,0.25"), ("crowd", "10") or ("robot_control", "external").
  std::vector<std::pair<std::string, std::string>> overrides;
  /// Completion codes (SEAN-EP's t1 and t2): shown to the participant and sent to the survey on success and
  /// on timeout; identifiers, empty when the link has none.
  std::string code_success;
  std::string code_timeout;
  /// `exp`: the link is valid until this Unix time, seconds (signed with the rest when links are signed);
  /// unset = no expiry.
  std::optional<std::uint64_t> expires_at;
  /// `condition`: "interactive" (the default: the participant walks) or "video" (they watch a replay of a
  /// finished interactive session of the scenario, sessions/yoking.hpp).
  std::string condition = "interactive";
  /// `yoke_uid`: with condition=video on a signed link, the walker whose session is shown; "" = the manager
  /// chooses (yoke_policy).
  std::string yoke_uid;
};

/// The link parameters that override the scenario, with the sim_rfb flag each becomes: the poses, crowd (0..500)
/// robot_control (builtin or external) and camera (third_person or first_person).
struct OverrideParam {
  const char* name;  ///< in the link, e.g. "avatar_start"
  const char* flag;  ///< for sim_rfb, e.g. "--avatar-start"
};
extern const std::vector<OverrideParam> kOverrideParams;

/// The outcome of checking a link: a request, or the message a participant sees (4xx).
struct StartParse {
  std::optional<StartRequest> request;
  std::string error;
};

/// True for 1..64 letters, digits, '-' and '_': safe in paths, logs and command lines. The contract's, which
/// sim_rfb applies to the same uid and codes.
using contract::is_identifier;

/// A pose: a spawn point's name (an identifier) or "x,y,yaw" in metres and radians, strictly decimal.
bool is_pose(std::string_view text);

/// Validates the parameters of /start (`sig` is checked elsewhere and ignored here). A video link
/// (condition=video) shows a recording as it was: seed and the scenario overrides are refused with it, and
/// yoke_uid is refused without it. `scenarios` are the
/// allowed names; an absent scenario means the first. An empty list offers none (session kinds rfb and x11 without
/// scenarios): the scenario is "" and a link that names one is refused. Unknown parameters are refused.
StartParse parse_start_request(const QueryParams& params, const std::vector<std::string>& scenarios);

/// As above, then each pose override that names a spawn point must be one of the scenario's (`facts`, found by
/// name; a scenario without facts is not checked further), and robot_start, robot_goal and robot_control need a
/// robot:
/// "avatar_start 'dok' is not a spawn point of warehouse (known: dock, aisle_1, ...)".
StartParse parse_start_request(const QueryParams& params, const std::vector<std::string>& scenarios,
                               const std::vector<ScenarioFacts>& facts);

/// The allowed scenario names of a config's list, whose entries are NAME or NAME=FILE.
std::vector<std::string> scenario_names(const std::vector<std::string>& entries);

/// What sim_rfb is told for a scenario name: the FILE of a NAME=FILE entry, else the name itself.
std::string scenario_argument(const std::vector<std::string>& entries, const std::string& name);

}  // namespace rfbsim::manager
