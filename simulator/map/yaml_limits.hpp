// SPDX-License-Identifier: GPL-2.0-or-later
// Limits checked on a YAML file's text before yaml-cpp sees it. yaml-cpp parses nesting by recursion, so a
// file of "[[[[..." or "- - - - ..." costs stack in proportion to its depth; its own guard (500 levels in
// 0.7) ends with an unhelpful "bad file" after going that deep. Scenario and map files nest a handful of
// levels, so we refuse anything deeper, or larger, up front with a message that says which limit.
// Header-only and pure (no I/O), so the map loader and the scenario loader share it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace rfbsim::sim {

/// Most bytes a scenario or map YAML file may hold (ours hold a few kilobytes).
inline constexpr std::size_t kMaxYamlBytes = 1'000'000;
/// Deepest nesting of collections (mappings, sequences, flow [..] and {..}) a scenario or map file may
/// have; the shipped scenarios nest 5 deep.
inline constexpr int kMaxYamlDepth = 32;

/// The nesting depth of a YAML text as far as a linear scan can tell, and the first line (from 1) where
/// it went past the limit asked for (0 when it did not).
struct YamlDepth {
  int depth = 0;          ///< the deepest nesting seen (the scan stops early once past the limit)
  std::size_t line = 0;   ///< where the limit was passed, or 0
};

namespace yaml_limits_detail {

inline bool is_blank(char c) { return c == ' ' || c == '\t'; }

// What may end an indicator such as ": " or "- ": a blank, or a control character (yaml-cpp takes some of
// those for line breaks, so counting them here keeps the estimate on the deep side).
inline bool ends_indicator(char c) { return is_blank(c) || static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }

// Whether `rest` (from a '|' or '>' on) is a block scalar header: the indicator, at most a chomping sign
// and an indentation digit, then only blanks or a comment.
inline bool is_block_scalar_header(std::string_view rest) {
  std::size_t i = 1;
  while (i < rest.size() && i < 3 && (rest[i] == '-' || rest[i] == '+' || (rest[i] >= '1' && rest[i] <= '9'))) ++i;
  while (i < rest.size() && is_blank(rest[i])) ++i;
  return i == rest.size() || (rest[i] == '#' && is_blank(rest[i - 1]));
}

}  // namespace yaml_limits_detail

/// Scans `text` line by line and estimates how deep its collections nest: block collections by their
/// indentation (plus one per "- " or "? " that opens a compact one on a line), flow collections by their
/// brackets (plus the one-pair mappings that "key: value" makes inside '['), skipping comments, quoted
/// scalars and block scalars (| and >). The estimate is meant never to be below yaml-cpp's own depth for
/// text it accepts (the fuzz targets check this); it may be above, e.g. for odd plain scalars such as
/// "a: b[", which only makes the limit stricter. Stops at the first point deeper than `limit`.
inline YamlDepth yaml_nesting_depth(std::string_view text, int limit = kMaxYamlDepth) {
  using yaml_limits_detail::ends_indicator;
  using yaml_limits_detail::is_blank;
  YamlDepth result;
  // The enclosing block collections by indentation, innermost last. A level whose lines are both keys and
  // "- " items holds a sequence that shares its parent's indentation ("key:\n- a"): one more level.
  // yaml-cpp also nests each line that starts with an empty key (": ...") in the mapping before it, and
  // what follows deeper inside that (":\n:\n:\n" is three deep): such lines add a level each while their
  // level lasts.
  struct Level {
    std::size_t indent = 0;
    bool keys = false;
    bool items = false;
    int empty_keys = 0;
  };
  std::vector<Level> levels;
  int block = 0;                     // block depth of the current line, compact "- " levels included
  int flow = 0;                      // unclosed '[' and '{'
  // The unclosed brackets, innermost last. In a '[' an entry "key: value" is a one-pair mapping, one level
  // deeper ("[a: [b]]" nests three deep); `pair` says the current entry is one.
  struct Bracket {
    bool sequence = false;
    bool pair = false;
  };
  std::vector<Bracket> brackets;
  int pairs = 0;                     // brackets whose current entry is a pair
  int flow_empty_keys = 0;           // empty-key lines inside the current flow collection
  char quote = 0;                    // '\'' or '"' while inside a quoted scalar (it may span lines)
  std::size_t last_indent = 0;       // indentation of the last block-context line with content
  bool last_line_open = true;        // whether that line ended where a node may follow
  bool in_block_scalar = false;      // inside the text of a | or > scalar
  std::size_t block_scalar_indent = 0;  // the indentation of the line that opened it
  std::size_t line_no = 0;

  for (std::size_t pos = 0; pos <= text.size();) {
    const std::size_t eol = std::min(text.find('\n', pos), text.size());
    std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    std::size_t indent = 0;
    while (indent < line.size() && line[indent] == ' ') ++indent;
    std::size_t first = indent;  // the first character that is not a blank
    while (first < line.size() && is_blank(line[first])) ++first;
    const bool blank = first == line.size() || line[first] == '#';

    // A block scalar's text is every following line that is blank or indented deeper than its opener.
    if (in_block_scalar) {
      if (blank || indent > block_scalar_indent) continue;
      in_block_scalar = false;
    }
    std::size_t i = 0;
    // A line deeper than one that ended in a plain value continues that value ("a: b\n  'c" is the scalar
    // "b 'c"): nothing on it starts a node, not even a quote.
    bool token_start = true;
    if (quote == 0 && flow == 0 && !blank && indent > last_indent && !last_line_open) token_start = false;
    // yaml-cpp nests an empty-key line (": ...") inside a flow collection too.
    if (quote == 0 && flow > 0 && !blank && line[first] == ':' &&
        (first + 1 == line.size() || ends_indicator(line[first + 1]))) {
      ++flow_empty_keys;
    }
    if (quote == 0 && flow == 0) {
      if (blank) continue;
      // Block context: the line's indentation closes deeper collections and may open one more.
      const std::string_view start = line.substr(0, 3);
      if ((start == "---" || start == "...") && (line.size() == 3 || is_blank(line[3]))) {
        levels.clear();  // a new document
        i = 3;
      } else {
        while (!levels.empty() && levels.back().indent > indent) levels.pop_back();
        if (levels.empty() || levels.back().indent < indent) levels.push_back({indent, false, false, 0});
        const auto starts = [&](char indicator) {
          return line[indent] == indicator && (indent + 1 == line.size() || ends_indicator(line[indent + 1]));
        };
        (starts('-') ? levels.back().items : levels.back().keys) = true;
        if (starts(':')) ++levels.back().empty_keys;
        i = indent;
      }
      block = static_cast<int>(levels.size());
      for (const Level& level : levels) block += (level.keys && level.items ? 1 : 0) + level.empty_keys;
    }

    // The characters: `token_start` is true where a new node may begin (so a quote or bracket there is
    // YAML's indicator, not part of a plain scalar).
    bool after_json_node = false;  // just after a quoted scalar or a closing bracket (JSON-like "a":b)
    int block_colons = 0;          // "key: " indicators seen on this line in block context
    int dashes = 0;                // "- " indicators seen on this line in block context
    for (; i < line.size(); ++i) {
      const char c = line[i];
      const bool next_blank = i + 1 == line.size() || ends_indicator(line[i + 1]);
      if (quote != 0) {
        if (quote == '"' && c == '\\') {
          ++i;
        } else if (c == quote) {
          if (quote == '\'' && i + 1 < line.size() && line[i + 1] == '\'') {
            ++i;  // '' is a quote inside single quotes
          } else {
            quote = 0;
            token_start = false;
            after_json_node = true;
          }
        }
        continue;
      }
      if (is_blank(c)) continue;
      if (c == '#' && (i == 0 || is_blank(line[i - 1]))) break;  // a comment runs to the line's end
      const bool was_after_json = after_json_node;
      after_json_node = false;
      if ((c == '-' || c == '?') && token_start && next_blank) {
        if (flow == 0 && c == '-') {
          ++block;  // "- - x": each dash opens a sequence
          ++dashes;
        }
        if (flow == 0 && c == '?') ++block;  // "? " opens a complex key
      } else if (flow > 0 && (c == ':' || (c == '?' && token_start && next_blank))) {
        // In a flow sequence any ':' may make the entry a pair (even plain "a:b", to some parsers):
        // counting each costs at most one level per bracket, on the safe side.
        Bracket& inner = brackets.back();
        if (inner.sequence && !inner.pair) {
          inner.pair = true;
          ++pairs;
        }
        token_start = next_blank || was_after_json;
      } else if (c == ':' && next_blank) {
        // Block context. One "key: " per line is the line's own mapping, except after "- " (the mapping
        // is inside the item: "- a: b" is two deep even where the sequence shares its parent's
        // indentation); yaml-cpp reads some lines with more (": a{b: c") as a mapping inside the value, so
        // each further one counts a level too.
        if (block_colons++ > 0 || dashes > 0) ++block;
        token_start = true;
      } else if ((c == '[' || c == '{') && (token_start || flow > 0)) {
        ++flow;
        brackets.push_back({c == '[', false});
        token_start = true;
      } else if ((c == ']' || c == '}') && flow > 0) {
        --flow;
        if (brackets.back().pair) --pairs;
        brackets.pop_back();
        token_start = false;
        after_json_node = true;
      } else if (c == ',' && flow > 0) {
        if (brackets.back().pair) --pairs;
        brackets.back().pair = false;
        token_start = true;
      } else if ((c == '\'' || c == '"') && token_start) {
        quote = c;
      } else if ((c == '&' || c == '!' || c == '*') && token_start) {
        // An anchor, tag or alias: its name runs to a blank or a flow indicator (yaml-cpp reads "![a]" as a
        // tag and a sequence), and a node may follow.
        while (i + 1 < line.size() && !is_blank(line[i + 1]) &&
               std::string_view(",[]{}").find(line[i + 1]) == std::string_view::npos) {
          ++i;
        }
        token_start = c != '*';
      } else if ((c == '|' || c == '>') && token_start && flow == 0 &&
                 yaml_limits_detail::is_block_scalar_header(line.substr(i))) {
        in_block_scalar = true;
        block_scalar_indent = indent;
        break;
      } else {
        token_start = false;  // a plain scalar's character
      }
      const int depth = block + flow + pairs + flow_empty_keys;
      if (depth > result.depth) result.depth = depth;
      if (depth > limit) {
        result.line = line_no;
        return result;
      }
    }
    if (flow == 0) flow_empty_keys = 0;
    if (quote == 0 && flow == 0 && !blank) {
      last_indent = indent;
      last_line_open = token_start;  // ended after an indicator: a node may follow on the next line
    }
    // A line that ends inside a flow collection or quote goes on on the next, whatever its indentation.
    if (block > result.depth) result.depth = block;
    if (block > limit) {
      result.line = line_no;
      return result;
    }
  }
  return result;
}

/// Why `text` must not be handed to yaml-cpp, or "" when it is within kMaxYamlBytes and kMaxYamlDepth.
/// The caller puts the file's name in front, e.g. "lab.yaml: YAML nested more than 32 levels deep (line 3)".
inline std::string yaml_limits_problem(std::string_view text) {
  if (text.size() > kMaxYamlBytes) {
    return "too large for a YAML file here (over " + std::to_string(kMaxYamlBytes) + " bytes)";
  }
  const YamlDepth depth = yaml_nesting_depth(text, kMaxYamlDepth);
  if (depth.line != 0) {
    return "YAML nested more than " + std::to_string(kMaxYamlDepth) + " levels deep (line " +
           std::to_string(depth.line) + ")";
  }
  return "";
}

}  // namespace rfbsim::sim
