// SPDX-License-Identifier: GPL-2.0-or-later
// ProgressLine: what sim_replay prints on stderr during a long replay. On a terminal, one line redrawn in
// place ("\rsim_replay: 42.0 / 240.0 s simulated (17 %), 3.1x real time"); elsewhere (a log file), a line
// at every tenth of the way ("42.0 / 240.0 s simulated (17 %), 3.1x real time"), which the caller hands to the
// log sink as it does its other lines. Quiet while the replay is young, so a short one prints nothing. Pure: it
// returns the text and the caller writes it.
#pragma once

#include <string>

namespace rfbsim::replay {

class ProgressLine {
 public:
  /// `total_s`: simulated seconds to replay; `terminal`: stderr is a TTY; nothing is shown before
  /// `quiet_s` of wall time have passed.
  ProgressLine(double total_s, bool terminal, double quiet_s = 2.0);

  /// Text to print now that `done_s` simulated seconds are replayed, `elapsed_s` wall seconds after the start
  /// ("" for nothing): on a terminal, to write as it is; in a log, one line without its tag or newline.
  std::string step(double done_s, double elapsed_s);
  /// Text that ends the line: a newline after a terminal line that was drawn, else "".
  [[nodiscard]] std::string finish() const;

 private:
  double total_s_;
  bool terminal_;
  double quiet_s_;
  bool shown_ = false;
  double last_drawn_s_ = -1.0;  // wall time of the last terminal redraw
  int last_tenth_ = -1;         // the last tenth a log line was printed for
};

}  // namespace rfbsim::replay
