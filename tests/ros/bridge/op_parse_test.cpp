// SPDX-License-Identifier: GPL-2.0-or-later
// parse_op and its shape scan on hand-made frames: exact depths and value counts, strings that hide
// brackets, the two limits at and one past their edge, and the shape that made the old callback parser
// quadratic.
#include <catch2/catch.hpp>

#include <chrono>
#include <string>

#include "ros/bridge/op_parse.hpp"

using namespace rfbsim::ros;

namespace {

// {"op":"x","a":[0,0,...]} with `n` zeros: 1 + '{' + 2 ':' + 1 ',' + '[' + (n - 1) ',' = n + 5 values and keys.
std::string op_with_zeros(std::size_t n) {
  std::string text = R"({"op":"x","a":[0)";
  for (std::size_t i = 1; i < n; ++i) text += ",0";
  return text + "]}";
}

// An op whose "a" nests `depth` - 1 arrays inside its object (depth levels in all).
std::string op_nested(int depth) {
  return R"({"op":"x","a":)" + std::string(static_cast<std::size_t>(depth - 1), '[') +
         std::string(static_cast<std::size_t>(depth - 1), ']') + "}";
}

}  // namespace

TEST_CASE("the shape scan counts nesting and values outside strings only") {
  CHECK(scan_json_shape("").depth == 0);
  CHECK(scan_json_shape("").values == 1);
  CHECK(scan_json_shape("7").values == 1);
  const JsonShape op = scan_json_shape(R"({"op":"subscribe","topic":"/scan","id":3})");
  CHECK(op.depth == 1);
  CHECK(op.values == 1 + 1 + 3 + 2);  // the text, '{', three ':' and two ','
  CHECK(scan_json_shape(R"([[1,[2]],{"a":{}}])").depth == 3);
  // Brackets, commas and colons in strings, and escaped quotes that do not end them.
  const JsonShape quoted = scan_json_shape(R"({"k":"[[[{,:,:}]]] \" [[[ \\"})");
  CHECK(quoted.depth == 1);
  CHECK(quoted.values == 3);
  CHECK(scan_json_shape(R"(["\\",[[]]])").depth == 3);  // "\\" ends after the escaped backslash
}

TEST_CASE("parse_op takes 64 levels and refuses 65") {
  CHECK(parse_op(op_nested(kMaxJsonDepth)).error.empty());
  CHECK(parse_op(op_nested(kMaxJsonDepth + 1)).error.find("deeper than 64") != std::string::npos);
}

TEST_CASE("parse_op takes kMaxJsonValues values and keys and refuses one more, before parsing") {
  const ParsedOp at_limit = parse_op(op_with_zeros(kMaxJsonValues - 5));
  CHECK(at_limit.error.empty());
  CHECK(at_limit.message["a"].size() == kMaxJsonValues - 5);
  const ParsedOp over = parse_op(op_with_zeros(kMaxJsonValues - 4));
  CHECK(over.error == "JSON with more than 10000 values and keys");
  CHECK(over.message.is_null());
}

TEST_CASE("1 MiB of empty objects is refused at once, however it nests") {
  std::string text = R"({"op":"publish","topic":"/cmd_vel","msg":{"pad":[{})";
  while (text.size() < (std::size_t{1} << 20)) text += ",{}";
  text += "]}}";
  const auto started = std::chrono::steady_clock::now();
  const ParsedOp parsed = parse_op(text);
  const auto took = std::chrono::steady_clock::now() - started;
  CHECK(parsed.error.find("more than 10000 values") != std::string::npos);
  // A linear scan of 1 MiB: milliseconds, where the callback parser took seconds on this shape.
  CHECK(took < std::chrono::milliseconds(500));
}

TEST_CASE("below the limits, empty objects side by side parse in linear time") {
  // 4,990 objects, each counted twice (its '{' and the ',' before it): 9,985 in all, within the limit. The old
  // callback parser rescanned the array as each one ended, 12 million steps in all.
  std::string text = R"({"op":"x","a":[{})";
  for (int i = 1; i < 4990; ++i) text += ",{}";
  text += "]}";
  CHECK(scan_json_shape(text).values == 2 * 4990 + 5);
  const ParsedOp parsed = parse_op(text);
  REQUIRE(parsed.error.empty());
  CHECK(parsed.message["a"].size() == 4990);
}
