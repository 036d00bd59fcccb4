// SPDX-License-Identifier: GPL-2.0-or-later
// The ready pipe's lines: one writer per line and the one parser, so that a change to a line changes both.
#include "contract/ready_line.hpp"

#include <algorithm>
#include <charconv>

namespace rfbsim::contract {

namespace {

constexpr std::string_view kReadyUnix = "ready unix ";
constexpr std::string_view kReadyPort = "ready ";
constexpr std::string_view kX11Display = "x11 display ";
constexpr std::string_view kOutcome = "outcome ";
constexpr std::string_view kDataIncomplete = "data incomplete";
constexpr std::string_view kReason = "reason=";

bool line_has_prefix(std::string_view text, std::string_view prefix) { return text.substr(0, prefix.size()) == prefix; }

// 1..5 digits (no sign, space or '+', which sscanf let pass) within low..high.
std::optional<int> ready_number(std::string_view text, int low, int high) {
  if (text.empty() || text.size() > 5) return std::nullopt;
  if (!std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) return std::nullopt;
  int value = 0;
  std::from_chars(text.data(), text.data() + text.size(), value);
  if (value < low || value > high) return std::nullopt;
  return value;
}

ReadyLineParse ready_value(ReadyLine value) { return {std::move(value), ""}; }
ReadyLineParse ready_error(std::string error) { return {std::nullopt, std::move(error)}; }

}  // namespace

const char* task_end_name(TaskEnd end) {
  switch (end) {
    case TaskEnd::kCompleted: return "completed";
    case TaskEnd::kTimeout: return "timeout";
    case TaskEnd::kWatched: return "watched";
  }
  return "timeout";  // not reached: every value is named above
}

std::string ready_port_line(int port) { return std::string(kReadyPort) + std::to_string(port) + "\n"; }

std::string ready_unix_line(const std::string& path) { return std::string(kReadyUnix) + path + "\n"; }

std::string x11_display_line(int display) { return std::string(kX11Display) + std::to_string(display) + "\n"; }

std::string outcome_line(TaskEnd end) { return std::string(kOutcome) + task_end_name(end) + "\n"; }

std::string data_incomplete_line(const std::string& reason) {
  return std::string(kDataIncomplete) + " " + std::string(kReason) + reason + "\n";
}

ReadyLineParse parse_ready_line(std::string_view line) {
  if (is_stream_line(line)) {
    StreamParse stream = parse_stream_line(line);
    if (!stream.report) return ready_error(stream.error);
    return ready_value(std::move(*stream.report));
  }
  // Before "ready PORT", whose prefix it shares.
  if (line_has_prefix(line, kReadyUnix)) {
    const std::string_view path = line.substr(kReadyUnix.size());
    const bool clean = std::none_of(path.begin(), path.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; });
    if (path.empty() || !clean) return ready_error("not 'ready unix PATH'");
    return ready_value(ReadyUnix{std::string(path)});
  }
  if (line_has_prefix(line, kReadyPort)) {
    const auto port = ready_number(line.substr(kReadyPort.size()), 1, 65535);
    if (!port) return ready_error("not 'ready PORT'");
    return ready_value(ReadyPort{*port});
  }
  if (line_has_prefix(line, kX11Display)) {
    const auto display = ready_number(line.substr(kX11Display.size()), 0, 65535);
    if (!display) return ready_error("not 'x11 display N'");
    return ready_value(X11Display{*display});
  }
  if (line_has_prefix(line, kOutcome)) {
    const std::string_view end = line.substr(kOutcome.size());
    for (const TaskEnd known : {TaskEnd::kCompleted, TaskEnd::kTimeout, TaskEnd::kWatched}) {
      if (end == task_end_name(known)) return ready_value(TaskOutcomeLine{known});
    }
    return ready_error("not 'outcome completed', 'outcome timeout' or 'outcome watched'");
  }
  // "data incomplete", alone or with words after it; the reason is what follows the first "reason=".
  const std::string_view after_word = line.substr(std::min(line.size(), kDataIncomplete.size()));
  if (line_has_prefix(line, kDataIncomplete) && (after_word.empty() || after_word.front() == ' ')) {
    const std::size_t at = line.find(kReason);
    std::string reason;
    if (at != std::string_view::npos) reason = std::string(line.substr(at + kReason.size(), kMaxDataReason));
    if (reason.empty()) reason = "unknown";
    return ready_value(DataIncomplete{std::move(reason)});
  }
  return ready_error("not a line of the ready pipe");
}

}  // namespace rfbsim::contract
