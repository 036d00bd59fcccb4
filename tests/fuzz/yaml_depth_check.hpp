// SPDX-License-Identifier: GPL-2.0-or-later
// An invariant both YAML fuzz targets check: the nesting estimate that guards yaml-cpp is never below the
// depth of the tree yaml-cpp actually builds from text the guard let through.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string_view>

#include "fuzz_check.hpp"
#include "map/yaml_limits.hpp"

namespace rfbsim::fuzz {

/// The depth of `node`'s tree, counting collections only, stopping at `cap` (aliases can make cycles).
inline int yaml_tree_depth(const YAML::Node& node, int cap) {
  if (cap <= 0 || !(node.IsSequence() || node.IsMap())) return 0;
  int deepest = 0;
  for (const auto& item : node) {
    if (node.IsMap()) {
      deepest = std::max({deepest, yaml_tree_depth(item.first, cap - 1), yaml_tree_depth(item.second, cap - 1)});
    } else {
      deepest = std::max(deepest, yaml_tree_depth(item, cap - 1));
    }
  }
  return deepest + 1;
}

/// Checks the guard against yaml-cpp for `text` that passes the limits and has no alias (an alias repeats a
/// tree elsewhere, which is depth yaml-cpp never recursed for). The property that matters: nothing the guard
/// lets through nests deeper than twice its limit in yaml-cpp, so the recursion stays bounded. The estimate
/// aims to be exact or above for every construct (the unit tests pin the known ones); odd plain-scalar and
/// flow corners where yaml-cpp nests one level more than counted are tolerated as long as they cannot add up
/// past that bound.
inline void check_yaml_depth_estimate(std::string_view text) {
  if (!sim::yaml_limits_problem(text).empty() || text.find('*') != std::string_view::npos) return;
  const int bound = 2 * sim::kMaxYamlDepth;
  try {
    const YAML::Node root = YAML::Load(std::string(text));
    check(yaml_tree_depth(root, bound + 1) <= bound, "YAML the guard let through nests past twice its limit");
  } catch (const YAML::Exception&) {
    // Not YAML: the loaders report it.
  }
}

}  // namespace rfbsim::fuzz
