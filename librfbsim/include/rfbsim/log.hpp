// SPDX-License-Identifier: GPL-2.0-or-later
// One log sink for librfbsim and the programs built on it: a line "[tag] text" on stderr, filtered by a
// level (--log-level), and a rate limit for every line an outsider can cause (a client's bad message, a
// flood of connections): past its budget, a kind of line is counted instead of written, and one
// "N more like this suppressed" line per kind and period says what was left out. Thread-safe.
// C++17, so that sim_manager (C++17 for websocketpp) shares it.
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <string_view>

namespace rfbsim::log {

/// From the most to the least severe; a level shows its own lines and those above it.
enum class Level { kError = 0, kWarn = 1, kInfo = 2, kDebug = 3 };

/// The level below which lines are dropped (default kInfo).
void set_level(Level level);
[[nodiscard]] Level level();
[[nodiscard]] bool enabled(Level level);

/// "error", "warn", "info" or "debug" into `out`; false for anything else.
[[nodiscard]] bool parse_level(std::string_view text, Level& out);
/// Sets the level a --log-level option named; false (and the level unchanged) for a name parse_level refuses.
bool set_level(std::string_view name);
/// The names parse_level takes, for a --log-level option's help and choices.
inline constexpr const char* kLevelNames[] = {"error", "warn", "info", "debug"};

/// Writes "[tag] text" (and a newline) if `level` is enabled.
void write(Level level, std::string_view tag, std::string_view text);

/// printf-style shorthands for write(): rfbsim::log::info("manager", "session %d started", id).
void error(const char* tag, const char* format, ...) __attribute__((format(printf, 2, 3)));
void warn(const char* tag, const char* format, ...) __attribute__((format(printf, 2, 3)));
void info(const char* tag, const char* format, ...) __attribute__((format(printf, 2, 3)));
void debug(const char* tag, const char* format, ...) __attribute__((format(printf, 2, 3)));

/// The budget of each rate-limited kind of line: at most `lines` per `period`.
struct RateLimit {
  int lines = 5;
  std::chrono::steady_clock::duration period = std::chrono::seconds(10);
};
void set_rate_limit(RateLimit limit);

/// A line an outsider can cause, rate-limited by `kind` (a fixed name such as "bad-rfb-message", never text
/// from the outsider). Within the budget it is written as write() would; past it, it is counted; the first
/// line of `kind` in a later period first writes "[tag] N more like this suppressed (kind)".
void limited(Level level, const char* kind, const char* tag, const char* format, ...)
    __attribute__((format(printf, 4, 5)));

/// Writes the pending "suppressed" lines of every kind now (at exit, so that none is lost).
void flush_suppressed();

/// Where lines go (each without its newline); empty = stderr. For tests, and for programs that log elsewhere.
void set_sink(std::function<void(std::string_view line)> sink);

}  // namespace rfbsim::log
