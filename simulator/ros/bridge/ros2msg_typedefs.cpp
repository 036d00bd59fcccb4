// SPDX-License-Identifier: GPL-2.0-or-later
// ros2msg_typedefs: the .msg grammar as ROS 2's "Interface definition" page states it: one field or constant a line,
// "type name [default]" or "TYPE NAME=value"; "type[]" is unbounded, "type[<=N]" bounded, "type[N]" fixed;
// "string<=N" is a bounded string; a type without a package is from the message's own package.
#include "ros/bridge/ros2msg_typedefs.hpp"

#include <string>
#include <vector>

#include "ros/bridge/ros_names.hpp"

namespace rfbsim::ros {

namespace {

using nlohmann::json;

bool is_primitive(std::string_view type) {
  for (const char* name : {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
                           "uint32", "int64", "uint64", "string", "wstring"}) {
    if (type == name) return true;
  }
  return false;
}

// `text` without white space (blanks, tabs, line ends) at either end.
std::string_view trim(std::string_view text) {
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
}

// A field's type as TypeDef names it and its array length (-1, 0 or N); `package` resolves a bare nested type.
struct FieldType {
  std::string name;
  int array_length = -1;
};

FieldType field_type(std::string_view spec, const std::string& package) {
  FieldType out;
  if (const std::size_t open = spec.find('['); open != std::string_view::npos) {
    const std::string_view inside = spec.substr(open + 1, spec.find(']', open) - open - 1);
    out.array_length = 0;
    if (!inside.empty() && inside.front() != '<') {
      int length = 0;
      for (const char c : inside) length = c >= '0' && c <= '9' ? length * 10 + (c - '0') : length;
      out.array_length = length;
    }
    spec = spec.substr(0, open);
  }
  if (const std::size_t bound = spec.find("<="); bound != std::string_view::npos) spec = spec.substr(0, bound);
  if (is_primitive(spec)) {
    out.name = std::string(spec);
  } else if (spec.find('/') != std::string_view::npos) {
    out.name = normalize_ros_type(spec);
  } else {
    out.name = package + "/msg/" + std::string(spec);
  }
  return out;
}

// rosapi's example value of a field: what an empty message of the type holds.
std::string example(const FieldType& type) {
  if (type.array_length != -1) return "[]";
  if (!is_primitive(type.name)) return "{}";
  if (type.name == "bool") return "False";
  if (type.name == "string" || type.name == "wstring") return "";
  return "0";
}

// One block's TypeDef: `name` normalized, `body` its lines.
json typedef_of(const std::string& name, std::string_view body) {
  const std::string package = name.substr(0, name.find('/'));
  json def = {{"type", name},
              {"fieldnames", json::array()},
              {"fieldtypes", json::array()},
              {"fieldarraylen", json::array()},
              {"examples", json::array()},
              {"constnames", json::array()},
              {"constvalues", json::array()}};
  while (!body.empty()) {
    const std::size_t end = body.find('\n');
    std::string_view line = trim(body.substr(0, end));
    body = end == std::string_view::npos ? std::string_view() : body.substr(end + 1);
    if (line.empty() || line.front() == '#') continue;
    // The type, then the name (a constant's runs up to its '='), then a default value or a constant's value.
    const std::size_t space = line.find_first_of(" \t");
    if (space == std::string_view::npos) continue;
    const FieldType type = field_type(line.substr(0, space), package);
    const std::string_view rest = trim(line.substr(space));
    const std::size_t name_end = rest.find_first_of(" \t=");
    const std::string_view field = rest.substr(0, name_end);
    const std::string_view after =
        name_end == std::string_view::npos ? std::string_view() : trim(rest.substr(name_end));
    if (!after.empty() && after.front() == '=') {
      def["constnames"].push_back(std::string(field));
      def["constvalues"].push_back(std::string(trim(after.substr(1))));
      continue;
    }
    def["fieldnames"].push_back(std::string(field));
    def["fieldtypes"].push_back(type.name);
    def["fieldarraylen"].push_back(type.array_length);
    def["examples"].push_back(example(type));
  }
  return def;
}

}  // namespace

json ros2msg_typedefs(std::string_view type, std::string_view definition) {
  json defs = json::array();
  std::string name = normalize_ros_type(type);
  if (name.empty() || trim(definition).empty()) return defs;
  // Blocks are parted by a line of '=' characters; each after the first opens with "MSG: pkg/Type".
  std::size_t start = 0;
  while (start <= definition.size()) {
    std::size_t rule = definition.find("\n==", start);
    const std::size_t end = rule == std::string_view::npos ? definition.size() : rule + 1;
    std::string_view body = definition.substr(start, end - start);
    if (start != 0) {
      const std::size_t header_end = body.find('\n');
      const std::string_view header = trim(body.substr(0, header_end));
      if (header.substr(0, 4) != "MSG:") break;
      name = normalize_ros_type(trim(header.substr(4)));
      if (name.empty()) break;
      body = header_end == std::string_view::npos ? std::string_view() : body.substr(header_end + 1);
    }
    defs.push_back(typedef_of(name, body));
    if (rule == std::string_view::npos) break;
    // Past the rule line.
    const std::size_t rule_end = definition.find('\n', rule + 1);
    if (rule_end == std::string_view::npos) break;
    start = rule_end + 1;
  }
  return defs;
}

}  // namespace rfbsim::ros
