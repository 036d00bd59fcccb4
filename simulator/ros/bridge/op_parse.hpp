// SPDX-License-Identifier: GPL-2.0-or-later
// parse_op: one rosbridge text frame to a JSON object with a string "op", or the reason it is not one.
// Shared by the server's sessions and the dial-out link; pure, so the fuzz and unit tests reach it directly.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace rfbsim::ros {

/// A parsed frame: `error` is "" and `message` an object with a string "op", or `error` says what is wrong
/// (malformed JSON, nesting too deep, not an object, no "op") and `message` is whatever parsed (maybe null).
struct ParsedOp {
  nlohmann::json message;
  std::string error;
};

/// Nesting deeper than this is refused: no ROS message we take needs more, and a deep one would cost stack.
inline constexpr int kMaxJsonDepth = 64;

/// Parses `text` as one rosbridge message.
ParsedOp parse_op(std::string_view text);

/// The operation's "id" as given (string or integer), or null when absent or of another type.
nlohmann::json op_id(const nlohmann::json& message);

}  // namespace rfbsim::ros
