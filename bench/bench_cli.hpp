// SPDX-License-Identifier: GPL-2.0-or-later
// A benchmark's command line: each option declared once in a line or two (name, variable, range, help), with
// cli/'s conventions (decimal numbers in a range, one-line errors, --help with ranges and defaults) and the value
// kinds benchmarks take (sizes, comma-separated lists).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "cli/command_line.hpp"

namespace rfbsim::bench {

// The checks of cli/ that benchmarks use as they are.
using cli::non_empty;
using cli::one_of;
using cli::satisfies;

/// How a default is shown in --help.
inline std::string to_text(int value) { return std::to_string(value); }
inline std::string to_text(const std::string& value) { return value; }
inline std::string to_text(const Size& value) { return value.text(); }

/// `values` shown as a default: "a,b,c", each item by `show`.
template <typename T, typename Show>
std::string joined(const std::vector<T>& values, Show show) {
  std::string text;
  for (const T& item : values) text += (text.empty() ? "" : ",") + std::string(show(item));
  return text;
}

/// One benchmark's options. Declare them, then parse(); read the bound variables.
class CommandLine {
 public:
  /// `name` is the program's, `description` says what it measures (the help's first paragraph).
  CommandLine(const std::string& name, const std::string& description) : app_(description, name) {
    cli::configure(app_);
    app_.add_flag("-h,--help", help_, "print this help and exit");
  }

  /// An integer in [low, high].
  template <typename T>
  CLI::Option* number(const std::string& name, T& value, T low, T high, const std::string& help) {
    return app_.add_option(name, value, help)->type_name("N")->capture_default_str()->transform(cli::in_range(low, high));
  }
  /// A text: a path, a name (not empty).
  CLI::Option* text(const std::string& name, std::string& value, const std::string& help) {
    return app_.add_option(name, value, help)->type_name("TEXT")->capture_default_str()->check(cli::non_empty());
  }
  /// A flag that sets `value`.
  CLI::Option* flag(const std::string& name, bool& value, const std::string& help) {
    return app_.add_flag(name, value, help);
  }
  /// A value that `convert` turns into a T (throwing std::invalid_argument with a message that names the problem).
  template <typename T, typename Convert>
  CLI::Option* value(const std::string& name, T& out, Convert convert, const std::string& help) {
    return app_
        .add_option_function<std::string>(
            name, [&out, convert](const std::string& text) { out = convert(text); }, help)
        ->type_name("TEXT");
  }
  /// A "WIDTHxHEIGHT" size.
  CLI::Option* size(const std::string& name, Size& out, const std::string& help) {
    return value(name, out, [](const std::string& text) { return parse_sizes(text).at(0); }, help)
        ->type_name("WxH")->default_str(out.text());
  }
  /// A comma-separated list, each item turned into a T by `convert` (which throws std::invalid_argument); the
  /// help shows the default list with `show` per item.
  template <typename T, typename Convert, typename Show>
  CLI::Option* list(const std::string& name, std::vector<T>& values, Convert convert, Show show,
                    const std::string& help) {
    const std::string shown = joined(values, show);
    return value(name, values,
                 [convert](const std::string& text) {
                   std::vector<T> items;
                   for (const std::string& item : split_list(text)) items.push_back(convert(item));
                   return items;
                 },
                 help)
        ->type_name("A,B,...")->default_str(shown);
  }
  /// The same for items to_text() shows (numbers, names, sizes).
  template <typename T, typename Convert>
  CLI::Option* list(const std::string& name, std::vector<T>& values, Convert convert, const std::string& help) {
    return list(name, values, convert, [](const T& item) { return to_text(item); }, help);
  }

  /// Whether option `name` was given.
  [[nodiscard]] bool given(const std::string& name) const { return app_.count(name) > 0; }
  /// The whole CLI11 app, for what the helpers above do not cover.
  CLI::App& app() { return app_; }

  /// Parses argv: on --help prints the help and exits 0; on a bad argument throws std::invalid_argument.
  void parse(int argc, char** argv) {
    const std::string error = cli::parse(app_, std::vector<std::string>(argv + 1, argv + argc));
    if (help_) {
      std::fputs(app_.help().c_str(), stdout);
      std::exit(0);
    }
    if (!error.empty()) throw std::invalid_argument(error);
  }

 private:
  CLI::App app_;
  bool help_ = false;
};

/// Turns a list item into an integer in [low, high] (for CommandLine::list); `what` names it in an error.
inline auto int_in(int low, int high, const std::string& what) {
  return [low, high, what](const std::string& item) { return parse_int(item, low, high, what); };
}

/// Keeps a list item that is one of `names` (for CommandLine::list); `what` names the option in the error.
inline auto item_of(std::vector<std::string> names, const std::string& what) {
  return [names = std::move(names), what](const std::string& item) {
    if (std::find(names.begin(), names.end(), item) != names.end()) return item;
    std::string expected;
    for (std::size_t i = 0; i < names.size(); ++i) {
      expected += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
    }
    throw std::invalid_argument(what + ": '" + item + "' is not " + expected);
  };
}

/// A key given as one character (for CommandLine::value), as its keysym.
inline std::uint32_t parse_key(const std::string& text) {
  if (text.size() != 1) throw std::invalid_argument("--key takes one character");
  return static_cast<unsigned char>(text[0]);
}

}  // namespace rfbsim::bench
