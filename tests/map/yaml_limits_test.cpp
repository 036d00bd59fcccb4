// SPDX-License-Identifier: GPL-2.0-or-later
// The YAML size and nesting limits checked before yaml-cpp parses a scenario or map file: the shipped files
// pass, deep text of every kind of nesting is caught, and what only looks deep (quotes, comments, block
// scalars) is not counted.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "map/yaml_limits.hpp"

using namespace rfbsim::sim;

namespace {

std::string repeat(const std::string& piece, int times) {
  std::string out;
  for (int i = 0; i < times; ++i) out += piece;
  return out;
}

// A block mapping `levels` deep: "a:\n  a:\n    a: 1\n".
std::string block_mapping(int levels) {
  std::string out;
  for (int i = 0; i < levels; ++i) {
    out += std::string(static_cast<std::size_t>(2 * i), ' ') + (i + 1 < levels ? "a:\n" : "a: 1\n");
  }
  return out;
}

int depth_of(const std::string& text) { return yaml_nesting_depth(text, 1000).depth; }

}  // namespace

TEST_CASE("yaml limits: the depth of small documents is counted exactly") {
  CHECK(depth_of("") == 0);
  CHECK(depth_of("# only a comment\n") == 0);
  CHECK(depth_of("a: 1\nb: 2\n") == 1);
  CHECK(depth_of("a: [1, 2]\n") == 2);
  CHECK(depth_of("a: {b: [1, {c: 2}]}\n") == 4);
  CHECK(depth_of("a:\n  b:\n    - 1\n    - 2\n") == 4);  // mapping, mapping, the sequence's indentation, dash
  CHECK(depth_of("- - - x\n") == 4);
  // A line counts as one block level even when it holds a flow node: one above yaml-cpp, on the safe side.
  CHECK(depth_of("[[[1]]]\n") == 4);
  // "key: value" in a flow sequence is a one-pair mapping: a level of its own.
  CHECK(depth_of("a: [b: [c]]\n") == 4);
  CHECK(depth_of("a: [b: 1, c, d: 2]\n") == 3);
  CHECK(depth_of("a: [\n  b: 1, ...c: 2]\n") == 3);
  // yaml-cpp reads ": a{b: c" as a mapping in a mapping: a second "key: " on a line counts a level.
  CHECK(depth_of(": imro{image: imroa") >= 2);
  // A mapping in a sequence item is a level of its own, even where the sequence shares its parent's
  // indentation (yaml-cpp: 12 deep).
  CHECK(depth_of("mas:\n  p& a :[1.0, s:\n  - - - - - - - - - -l: b\n") >= 12);
  // ...and so are the lines below its items (yaml-cpp: 6 deep at "c").
  CHECK(depth_of("a:\n  m:\n  - k: 1\n    s: {c: [1]}\n") >= 6);
  // yaml-cpp takes some control characters for line breaks: ":\x04:" is two deep.
  CHECK(depth_of(":\x04:") >= 2);
  // An empty-key line nests what is indented below it too (yaml-cpp: 4 deep), and a tag may touch its node.
  CHECK(depth_of("s:\n:\n    a: [5.0]\n") >= 4);
  CHECK(depth_of("o: ![1, 2]\n") >= 2);
  // A quote that continues a plain scalar opens nothing; empty-key lines nest inside flow collections too.
  CHECK(depth_of("a: b]\n    'c\nd: [[1]]\n") >= 3);
  CHECK(depth_of("{a: 1,\n:\n:\n:\n}\n") >= 4);
  // yaml-cpp nests each line that starts with an empty key in the one before: ":\n:\n:\n" is 3 deep.
  CHECK(depth_of(":\n:\n:\n") >= 3);
  CHECK(depth_of("a:\n:\n:\n") >= 3);
  CHECK(depth_of(block_mapping(10)) == 10);
}

TEST_CASE("yaml limits: the shipped scenarios and maps are well inside the limits") {
  for (const char* name : {"lab.yaml", "tutorial.yaml", "warehouse.yaml", "maps/lab.yaml", "maps/warehouse.yaml"}) {
    INFO(name);
    std::ifstream in(std::string(RFBSIM_SCENARIO_DIR) + "/" + name);
    REQUIRE(in);
    std::ostringstream text;
    text << in.rdbuf();
    CHECK(yaml_limits_problem(text.str()).empty());
    CHECK(depth_of(text.str()) <= 8);
  }
}

TEST_CASE("yaml limits: deep nesting of every kind is refused with the limit and the line") {
  const int too_deep = kMaxYamlDepth + 1;
  for (const std::string& text : {repeat("[", too_deep) + repeat("]", too_deep), repeat("{a: ", too_deep),
                                  repeat("- ", too_deep) + "x\n", block_mapping(too_deep),
                                  "a: &x " + repeat("[", too_deep), "a: !!seq " + repeat("[", too_deep),
                                  "--- " + repeat("[", too_deep), "a:\n  [\n" + repeat("[\n", too_deep),
                                  repeat(":\n", too_deep)}) {
    INFO(text.substr(0, 80));
    const std::string problem = yaml_limits_problem(text);
    CHECK_THAT(problem, Catch::Contains("nested more than " + std::to_string(kMaxYamlDepth) + " levels deep"));
  }
  CHECK(yaml_limits_problem("ok: 1\n" + repeat("[", 1000)) ==
        "YAML nested more than " + std::to_string(kMaxYamlDepth) + " levels deep (line 2)");
  // Exactly at the limit passes.
  CHECK(yaml_limits_problem(repeat("[", kMaxYamlDepth - 1) + repeat("]", kMaxYamlDepth - 1)).empty());
  CHECK(yaml_limits_problem(block_mapping(kMaxYamlDepth)).empty());
}

TEST_CASE("yaml limits: brackets in quotes, comments and block scalars do not count") {
  const std::string brackets = repeat("[", 100);
  CHECK(depth_of("a: \"" + brackets + "\"\n") == 1);
  CHECK(depth_of("a: '" + brackets + "'\n") == 1);
  CHECK(depth_of("a: 'it''s " + brackets + "'\n") == 1);
  CHECK(depth_of("a: \"\\\" " + brackets + "\"\n") == 1);
  CHECK(depth_of("a: 1  # " + brackets + "\n") == 1);
  CHECK(depth_of("a: |\n  " + brackets + "\n      deeper text\n          and deeper\nb: 1\n") == 1);
  CHECK(depth_of("a: >-\n  text\n\n  more\nb: [1]\n") == 2);
  // A quote inside a plain scalar does not open a quoted one: the brackets after it still count.
  CHECK(depth_of("a: don't\nb: [[1]]\n") == 3);
  // Quoted JSON keys: "a":[...] nests.
  CHECK(depth_of("{\"a\":[[1]]}\n") == 4);
}

TEST_CASE("yaml limits: text over the size limit is refused before it is scanned") {
  const std::string big(kMaxYamlBytes + 1, ' ');
  CHECK(yaml_limits_problem(big) ==
        "too large for a YAML file here (over " + std::to_string(kMaxYamlBytes) + " bytes)");
  CHECK(yaml_limits_problem(std::string(kMaxYamlBytes, ' ')).empty());
}
