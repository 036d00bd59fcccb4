// SPDX-License-Identifier: GPL-2.0-or-later
// parse_op: the frame's shape from a linear scan (depth, values), then nlohmann::json's plain parser.
#include "ros/bridge/op_parse.hpp"

#include <algorithm>

namespace rfbsim::ros {

JsonShape scan_json_shape(std::string_view text) {
  JsonShape shape;
  shape.values = 1;  // the top-level value, preceded by none of the characters counted below
  int depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    // Inside a string only its end matters; "\"" and "\\" do not end it.
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    // Every value and key follows one of '{', '[', ',' or ':', or opens the text.
    switch (c) {
      case '"':
        in_string = true;
        break;
      case '{':
      case '[':
        ++shape.values;
        shape.depth = std::max(shape.depth, ++depth);
        break;
      case '}':
      case ']':
        --depth;  // below zero only in text the parser refuses anyway
        break;
      case ',':
      case ':':
        ++shape.values;
        break;
      default:
        break;
    }
  }
  return shape;
}

ParsedOp parse_op(std::string_view text) {
  ParsedOp parsed;
  const JsonShape shape = scan_json_shape(text);
  if (shape.depth > kMaxJsonDepth) {
    parsed.error = "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
    return parsed;
  }
  if (shape.values > kMaxJsonValues) {
    parsed.error = "JSON with more than " + std::to_string(kMaxJsonValues) + " values and keys";
    return parsed;
  }
  try {
    parsed.message = nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::exception& error) {
    parsed.error = std::string("malformed JSON: ") + error.what();
    return parsed;
  }
  if (!parsed.message.is_object()) {
    parsed.error = "a rosbridge message is a JSON object";
  } else if (!parsed.message.contains("op") || !parsed.message["op"].is_string()) {
    parsed.error = "missing or non-string \"op\"";
  }
  return parsed;
}

nlohmann::json op_id(const nlohmann::json& message) {
  if (!message.is_object() || !message.contains("id")) return nullptr;
  const nlohmann::json& id = message.at("id");
  if (!(id.is_string() || id.is_number_integer())) return nullptr;
  return id;
}

}  // namespace rfbsim::ros
