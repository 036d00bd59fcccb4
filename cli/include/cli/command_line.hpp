// SPDX-License-Identifier: GPL-2.0-or-later
// Our programs' command lines: CLI11 with the conventions every program shares.
//
// Each option is declared once on a CLI::App (name, bound variable, help, default, range or choices); parsing and
// --help both follow from that declaration. What this header adds to CLI11:
//   - numbers are decimal only and checked against a range (CLI11 alone reads "010" as octal and "-1" as a huge
//     unsigned value);
//   - choices and other checks name what was expected;
//   - errors read as one short line in our words ("bad value 'x' for --port", "--port needs a value",
//     "unknown argument '--x'"), and parsing never throws;
//   - --help lists each option with its range and default taken from the declaration.
#pragma once

#include <CLI/CLI.hpp>

#include "rfbsim/log.hpp"

#include <algorithm>
#include <charconv>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

namespace rfbsim::cli {

/// The help's layout: "--port N   TCP port (0..65535; default 5901)". The type name stays beside the option;
/// the range (a check's description) and the default go to the end of the help text.
class Formatter : public CLI::Formatter {
 public:
  Formatter() {
    label("Usage", "usage");
    column_width(26);
  }
  // The usage line first, then what the program does.
  std::string make_description(const CLI::App*) const override { return {}; }
  std::string make_usage(const CLI::App* app, std::string name) const override {
    const std::string description = CLI::Formatter::make_description(app);
    return CLI::Formatter::make_usage(app, std::move(name)) + (description.empty() ? "" : "\n" + description);
  }
  std::string make_option_opts(const CLI::Option* option) const override {
    if (option->get_type_size() == 0 || !option->nonpositional()) return {};
    // get_type_name() is the type name, then ":" and each check's description; our type names hold no ":".
    const std::string type = option->get_type_name();
    return " " + type.substr(0, type.find(':'));
  }
  std::string make_option_desc(const CLI::Option* option) const override {
    std::string notes;
    const std::string type = option->get_type_name();
    if (option->get_type_size() != 0 && type.find(':') != std::string::npos) notes = type.substr(type.find(':') + 1);
    if (!option->get_default_str().empty()) {
      notes += (notes.empty() ? "" : "; ") + std::string("default ") + option->get_default_str();
    }
    return wrap(option->get_description() + (notes.empty() ? "" : " (" + notes + ")"));
  }

 private:
  // The help's lines end by column 110: CLI11 indents each line of a description after a '\n' to its column.
  std::string wrap(const std::string& text) const {
    const std::size_t width = 110 > get_column_width() + 30 ? 110 - get_column_width() : 30;
    std::string wrapped;
    std::size_t line_length = 0;
    std::size_t start = 0;
    while (start < text.size()) {
      std::size_t end = text.find(' ', start);
      if (end == std::string::npos) end = text.size();
      const std::size_t word = end - start;
      if (line_length > 0 && line_length + 1 + word > width) {
        wrapped += '\n';
        line_length = 0;
      } else if (line_length > 0) {
        wrapped += ' ';
        ++line_length;
      }
      wrapped += text.substr(start, word);
      line_length += word;
      start = end + 1;
    }
    return wrapped;
  }
};

/// Sets `app` up our way: no built-in --help (the program declares its own flag, so that asking for help
/// is an option like the others), a repeated option keeps its last value, and a flag takes no "=value".
inline void configure(CLI::App& app) {
  app.set_help_flag();
  app.formatter(std::make_shared<Formatter>());
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)->disable_flag_override();
}

/// Message of a check that says no more than "bad value": the option's name and the value tell the rest.
inline const std::string kBadValue = "bad value";

/// Accepts a decimal integer in [low, high] (no sign for unsigned types, no "+", no spaces, no other base) and
/// hands CLI11 its canonical spelling; the help shows "low..high". Give it with transform(), not check(): a check
/// may not rewrite the value, and CLI11 would then read "010" as octal.
template <typename T>
CLI::Validator in_range(T low, T high) {
  return CLI::Validator(
      [low, high](std::string& text) {
        T value{};
        const auto* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, value);
        if (ec != std::errc() || ptr != end || value < low || value > high) return kBadValue;
        text = std::to_string(value);
        return std::string();
      },
      std::to_string(low) + ".." + std::to_string(high));
}

/// Accepts the values for which `accept` is true; on any other, the error adds "(expected <expected>)" unless
/// `expected` is empty.
inline CLI::Validator satisfies(std::function<bool(const std::string&)> accept, const std::string& expected = {}) {
  return CLI::Validator(
      [accept = std::move(accept), expected](std::string& text) {
        if (accept(text)) return std::string();
        return expected.empty() ? kBadValue : "expected " + expected;
      },
      std::string());
}

/// Accepts any value but the empty one (a name, a path, an address).
inline CLI::Validator non_empty() {
  return satisfies([](const std::string& text) { return !text.empty(); });
}

/// "a, b or c" for names {a, b, c}: how an error names the choices.
inline std::string spoken_list(const std::vector<std::string>& names) {
  std::string spoken;
  for (std::size_t i = 0; i < names.size(); ++i) {
    spoken += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  return spoken;
}

/// "a|b|c" for names {a, b, c}: how the help names the choices.
inline std::string bar_list(const std::vector<std::string>& names) {
  std::string joined;
  for (std::size_t i = 0; i < names.size(); ++i) joined += (i == 0 ? "" : "|") + names[i];
  return joined;
}

/// Makes `option` accept one of `names` only: the help shows "a|b|c", an error says "(expected a, b or c)".
inline CLI::Option* one_of(CLI::Option* option, const std::vector<std::string>& names) {
  option->type_name(bar_list(names));
  return option->check(
      satisfies([names](const std::string& text) { return std::find(names.begin(), names.end(), text) != names.end(); },
                spoken_list(names)));
}

namespace detail {

// The first of `option`'s values that one of its checks rejects (CLI11 stops at it), or "" if none does.
inline std::string rejected_value(CLI::Option& option) {
  for (const std::string& value : option.results()) {
    for (int index = 0;; ++index) {
      const CLI::Validator* check = nullptr;
      try {
        check = option.get_validator(index);
      } catch (const CLI::OptionNotFound&) {
        break;
      }
      std::string copy = value;
      if (!(*check)(copy).empty()) return value;
    }
  }
  return {};
}

// The option CLI11 names before `suffix` in its message ("--port: ...", or "debug-overlay was given ..." without
// the dashes), as the user spells it; "" if the text there names none of app's options.
inline std::string option_named_in(CLI::App& app, const std::string& message, const std::string& suffix) {
  const auto end = message.find(suffix);
  if (end == std::string::npos) return {};
  for (const std::string& name : {message.substr(0, end), "--" + message.substr(0, end)}) {
    if (app.get_option_no_throw(name) != nullptr) return name;
  }
  return {};
}

}  // namespace detail

/// --log-level, bound to `level` (its initial value is the default): the names of rfbsim/log.hpp's levels,
/// which the program hands to rfbsim::log::parse_level once parsing is done.
inline CLI::Option* add_log_level(CLI::App& app, std::string& level) {
  return one_of(app.add_option("--log-level", level, "the log's level")->type_name("L")->capture_default_str(),
                std::vector<std::string>(std::begin(rfbsim::log::kLevelNames), std::end(rfbsim::log::kLevelNames)));
}

/// Parses `args` (argv without the program name) into the variables `app`'s options are bound to. Returns "" on
/// success, else one line naming the first bad argument. Never throws, never exits, prints nothing.
inline std::string parse(CLI::App& app, const std::vector<std::string>& args) noexcept {
  try {
    try {
      std::vector<std::string> last_first(args.rbegin(), args.rend());  // as CLI11 takes them (and uses them up)
      app.parse(last_first);
      return {};
    } catch (const CLI::ExtrasError&) {
      const auto extras = app.remaining();
      return "unknown argument '" + (extras.empty() ? std::string() : extras.front()) + "'";
    } catch (const CLI::ValidationError& error) {
      // Options are checked in declaration order: the first one given whose callback has not run is the one.
      for (CLI::Option* option : app.get_options()) {
        if (option->count() == 0 || option->get_callback_run()) continue;
        // CLI11's text is "<name>: <what the check said>".
        const std::string name = option->get_name();
        const std::string message = error.what();
        const std::string reason = message.size() > name.size() + 2 ? message.substr(name.size() + 2) : kBadValue;
        return "bad value '" + detail::rejected_value(*option) + "' for " + name +
               (reason == kBadValue ? "" : " (" + reason + ")");
      }
      return error.what();
    } catch (const CLI::ArgumentMismatch& error) {
      // "--port: 1 required N missing" (the value is missing), "--port: At Most 1 required but received 2" (an
      // option that may be given once, where the program says so) or "--flag was given a disallowed flag override".
      const std::string message = error.what();
      if (const auto name = detail::option_named_in(app, message, ": "); !name.empty()) {
        return name + (message.find(": At Most ") != std::string::npos ? " is given more than once" : " needs a value");
      }
      if (const auto name = detail::option_named_in(app, message, " was given"); !name.empty()) {
        // CLI11 names the flag only; the argument as given is the first that spells it with "=".
        const auto given = std::find_if(args.begin(), args.end(),
                                        [&](const std::string& arg) { return arg.rfind(name + "=", 0) == 0; });
        return "unknown argument '" + (given != args.end() ? *given : name + "=...") + "'";
      }
      return message;
    }
  } catch (const std::exception& error) {
    return error.what();
  }
}

}  // namespace rfbsim::cli
