// SPDX-License-Identifier: GPL-2.0-or-later
// parse_op: one rosbridge text frame to a JSON object with a string "op", or the reason it is not one.
// Shared by the server's sessions and the dial-out link; pure, so the fuzz and unit tests reach it directly.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace rfbsim::ros {

/// A parsed frame: `error` is "" and `message` an object with a string "op", or `error` says what is wrong
/// (malformed JSON, nesting too deep, too many values, not an object, no "op") and `message` is whatever
/// parsed (maybe null).
struct ParsedOp {
  nlohmann::json message;
  std::string error;
};

/// Nesting of arrays and objects deeper than this is refused: no ROS message we take needs more, and a deep
/// one would cost stack (copying and dumping a JSON value recurse).
inline constexpr int kMaxJsonDepth = 64;
/// Values and keys in one frame at most. Parsed, each costs up to ~100 bytes beyond its text (a value, a map
/// node, an allocation), so that "[{},{},...]" would make 1 MiB of text some 30 MB of memory; this keeps a
/// frame's parse within its text plus ~1 MB. A Twist has about 20, a subscribe op about 10.
inline constexpr std::size_t kMaxJsonValues = 10'000;

/// How a frame's text nests and how many values and keys it holds at most, from one pass over the text
/// outside its strings. For text that parses (and every prefix a parser reads before refusing the rest), the
/// parse goes no deeper and holds no more than this says.
struct JsonShape {
  int depth = 0;           ///< the most arrays and objects open at once
  /// An upper bound on values and keys: 1 + each '{', '[', ',' and ':'. An empty object counts twice (its
  /// '{' and what came before it), as its own allocation costs about as much as a second value.
  std::size_t values = 0;
};
JsonShape scan_json_shape(std::string_view text);

/// Parses `text` as one rosbridge message. Linear in its length: the shape is checked first, then the text
/// parsed without a callback (nlohmann's callback parser rescans a container's elements as each child object
/// ends, which made one 1 MiB frame of "[{},{},...]" cost sim_rfb's network thread 17 s).
ParsedOp parse_op(std::string_view text);

/// The operation's "id" as given (string or integer), or null when absent or of another type.
nlohmann::json op_id(const nlohmann::json& message);

}  // namespace rfbsim::ros
