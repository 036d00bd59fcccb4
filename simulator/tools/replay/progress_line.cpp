// SPDX-License-Identifier: GPL-2.0-or-later
// ProgressLine: terminal and log forms.
#include "progress_line.hpp"

#include <algorithm>
#include <cstdio>

namespace rfbsim::replay {

namespace {

constexpr double kRedrawEvery = 0.25;  // s of wall time between terminal redraws

}  // namespace

ProgressLine::ProgressLine(double total_s, bool terminal, double quiet_s)
    : total_s_(total_s), terminal_(terminal), quiet_s_(quiet_s) {}

std::string ProgressLine::step(double done_s, double elapsed_s) {
  if (total_s_ <= 0.0 || elapsed_s < quiet_s_) return "";
  done_s = std::clamp(done_s, 0.0, total_s_);
  const int percent = static_cast<int>(done_s / total_s_ * 100.0);
  const int tenth = percent / 10;
  if (terminal_ ? elapsed_s - last_drawn_s_ < kRedrawEvery : tenth <= last_tenth_) return "";
  last_drawn_s_ = elapsed_s;
  last_tenth_ = tenth;
  shown_ = true;
  char line[160];
  std::snprintf(line, sizeof line, "%s%.1f / %.1f s simulated (%d %%), %.1fx real time%s",
                terminal_ ? "\rsim_replay: " : "", done_s, total_s_, percent,
                elapsed_s > 0.0 ? done_s / elapsed_s : 0.0, terminal_ ? "   " : "");
  return line;
}

std::string ProgressLine::finish() const { return terminal_ && shown_ ? "\n" : ""; }

}  // namespace rfbsim::replay
