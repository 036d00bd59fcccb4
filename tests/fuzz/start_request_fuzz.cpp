// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: the /start link parser, from the raw query string as a participant's browser sends it.
// Invariants: a link gives either a request or a reason, never both; a request's uid, codes and scenario
// are identifiers from the allowed list, its overrides are known ones with valid values in the fixed
// order; reasons are short (they are shown on a page).
#include <string>
#include <vector>

#include "fuzz_check.hpp"
#include "http/query.hpp"
#include "admission/start_request.hpp"

using rfbsim::fuzz::check;
using namespace rfbsim::manager;

namespace {

std::size_t override_index(const std::string& name) {
  for (std::size_t i = 0; i < kOverrideParams.size(); ++i) {
    if (name == kOverrideParams[i].name) return i;
  }
  return kOverrideParams.size();
}

// A crowd size as the link's rule says: a whole number 0..500 in at most 4 digits, digits only.
bool is_count(const std::string& value) {
  if (value.empty() || value.size() > 4) return false;
  for (const char ch : value) {
    if (ch < '0' || ch > '9') return false;
  }
  return std::stoi(value) <= 500;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = rfbsim::fuzz::as_text(data, size);
  // The pose syntax on its own, on the whole input.
  (void)is_pose(text);
  (void)is_identifier(text);

  std::string error;
  const auto params = parse_query(text, error);
  if (!params) return 0;
  const std::vector<std::string> scenarios = {"lab", "warehouse", "tutorial"};
  const StartParse parsed = parse_start_request(*params, scenarios);
  check(parsed.request.has_value() != !parsed.error.empty(), "both or neither of request and error");
  if (!parsed.request) {
    check(parsed.error.size() < 400, "error message not bounded");
    return 0;
  }
  const StartRequest& request = *parsed.request;
  check(is_identifier(request.uid), "uid not an identifier");
  check(request.code_success.empty() || is_identifier(request.code_success), "t1 not an identifier");
  check(request.code_timeout.empty() || is_identifier(request.code_timeout), "t2 not an identifier");
  bool offered = false;
  for (const auto& name : scenarios) offered = offered || name == request.scenario;
  check(offered, "scenario outside the allowed list");
  std::size_t last = 0;
  for (const auto& [name, value] : request.overrides) {
    const std::size_t index = override_index(name);
    check(index < kOverrideParams.size(), "unknown override passed");
    check(index >= last, "overrides out of their fixed order");
    last = index;
    const bool valid = name == "crowd"           ? is_count(value)
                       : name == "robot_control" ? (value == "builtin" || value == "external")
                       : name == "camera"        ? (value == "third_person" || value == "first_person")
                                                 : is_pose(value);
    check(valid, "override value not valid");
  }
  return 0;
}
