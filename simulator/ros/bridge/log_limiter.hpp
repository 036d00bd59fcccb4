// SPDX-License-Identifier: GPL-2.0-or-later
// LogLimiter: decides which of the bridge's log lines reach stderr. The dial-out client logs what a lab's
// server says and does, and that server is not ours: a hostile or broken one could send a megabyte of text
// per frame, many frames a second. Each line is cut to kMaxChars and made printable; per kind, an exact
// repeat of the last line is dropped (a server down for an hour costs one line) and at most one line a
// second gets through, the next one saying how many were suppressed. Thread-safe; a fake clock for tests.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>

namespace rfbsim::ros {

class LogLimiter {
 public:
  using Clock = std::chrono::steady_clock;

  /// A limiter on the real clock.
  LogLimiter() : LogLimiter([] { return Clock::now(); }) {}
  /// A limiter on `now` (tests pass a fake clock).
  explicit LogLimiter(std::function<Clock::time_point()> now) : now_(std::move(now)) {}

  /// The line to print for `text` of `kind` (cut, printable, with a suppressed count in front when lines of
  /// this kind were dropped since the last one printed), or nullopt when it is to be dropped. Any thread.
  std::optional<std::string> admit(const std::string& kind, const std::string& text);

  /// Characters of a text kept at most ("..." follows a cut one).
  static constexpr std::size_t kMaxChars = 200;
  /// Least time between two printed lines of one kind.
  static constexpr std::chrono::seconds kInterval{1};

 private:
  struct Kind {
    std::string last;                     // the last text printed, as cut
    std::optional<Clock::time_point> at;  // when it was printed
    std::uint64_t suppressed = 0;         // lines dropped by the rate limit since
  };

  const std::function<Clock::time_point()> now_;
  std::mutex mutex_;  // guards kinds_
  std::map<std::string, Kind> kinds_;
};

}  // namespace rfbsim::ros
