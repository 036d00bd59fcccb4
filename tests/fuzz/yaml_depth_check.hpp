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

/// Checks the estimate against yaml-cpp for `text` that passes the limits and has no alias (an alias
/// repeats a tree elsewhere, which is depth yaml-cpp never recursed for).
inline void check_yaml_depth_estimate(std::string_view text) {
  if (!sim::yaml_limits_problem(text).empty() || text.find('*') != std::string_view::npos) return;
  const int estimate = sim::yaml_nesting_depth(text).depth;
  try {
    const YAML::Node root = YAML::Load(std::string(text));
    check(yaml_tree_depth(root, estimate + 1) <= estimate, "YAML nesting estimate below yaml-cpp's depth");
  } catch (const YAML::Exception&) {
    // Not YAML: the loaders report it.
  }
}

}  // namespace rfbsim::fuzz
