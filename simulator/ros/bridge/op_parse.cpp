// SPDX-License-Identifier: GPL-2.0-or-later
// parse_op over nlohmann::json's callback parser, which reports each value's depth as it goes, so that a
// deeply nested frame is refused while parsing instead of after.
#include "ros/bridge/op_parse.hpp"

#include <stdexcept>

namespace rfbsim::ros {

namespace {

struct TooDeep : std::runtime_error {
  TooDeep() : std::runtime_error("too deep") {}
};

}  // namespace

ParsedOp parse_op(std::string_view text) {
  ParsedOp parsed;
  const nlohmann::json::parser_callback_t limit_depth = [](int depth, nlohmann::json::parse_event_t,
                                                           nlohmann::json&) {
    if (depth > kMaxJsonDepth) throw TooDeep();
    return true;
  };
  try {
    parsed.message = nlohmann::json::parse(text.begin(), text.end(), limit_depth);
  } catch (const TooDeep&) {
    parsed.error = "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
    return parsed;
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
