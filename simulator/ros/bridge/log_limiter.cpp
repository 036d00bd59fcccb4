// SPDX-License-Identifier: GPL-2.0-or-later
// LogLimiter: cut, clean, then drop repeats and rate-limit per kind.
#include "ros/bridge/log_limiter.hpp"

namespace rfbsim::ros {

namespace {

// Untrusted text: at most LogLimiter::kMaxChars bytes, and no control byte reaches the terminal.
std::string printable_prefix(const std::string& text) {
  std::string cut = text.substr(0, LogLimiter::kMaxChars);
  for (char& c : cut) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (text.size() > LogLimiter::kMaxChars) cut += "...";
  return cut;
}

}  // namespace

std::optional<std::string> LogLimiter::admit(const std::string& kind, const std::string& text) {
  std::string line = printable_prefix(text);
  const Clock::time_point now = now_();
  const std::lock_guard lock(mutex_);
  Kind& state = kinds_[kind];
  // A retry failing as the last one did says nothing new.
  if (state.at && line == state.last) return std::nullopt;
  if (state.at && now - *state.at < kInterval) {
    ++state.suppressed;
    return std::nullopt;
  }
  state.last = line;
  state.at = now;
  if (state.suppressed > 0) {
    line = "(" + std::to_string(state.suppressed) + " more suppressed) " + line;
    state.suppressed = 0;
  }
  return line;
}

}  // namespace rfbsim::ros
