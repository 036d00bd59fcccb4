// SPDX-License-Identifier: GPL-2.0-or-later
// ProgressBar: what sim_report prints on stderr while it reads sessions. On a terminal, one line redrawn
// in place ("\r[#####.....] 12/372 sessions"); elsewhere (a log file), a line at every tenth of the way
// ("12/372 sessions (0 %)"), which the caller hands to the log sink as it does its other lines.
// Pure: it returns the text and the caller writes it.
#pragma once

#include <cstddef>
#include <string>

namespace rfbsim::report {

class ProgressBar {
 public:
  /// `total` sessions; `terminal`: stderr is a TTY. Quiet for `quiet_up_to` sessions or fewer unless a
  /// step reports more than `quiet_seconds` elapsed (a small report needs no bar; a slow one does).
  ProgressBar(std::size_t total, bool terminal, std::size_t quiet_up_to = 20, double quiet_seconds = 2.0);

  /// Text to print now that `done` of the sessions are done, `elapsed` s after the start ("" for nothing): on a
  /// terminal, to write as it is; in a log, one line without its tag or newline.
  std::string step(std::size_t done, double elapsed);
  /// Text that ends the bar: a newline after a terminal bar that was drawn, else "".
  std::string finish() const;

 private:
  std::size_t total_;
  bool terminal_;
  std::size_t quiet_up_to_;
  double quiet_seconds_;
  bool shown_ = false;        // anything printed yet
  std::size_t last_tenth_ = 0;  // the last tenth a log line was printed for
  std::string last_line_;     // the last terminal line drawn
};

}  // namespace rfbsim::report
