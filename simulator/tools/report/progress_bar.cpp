// SPDX-License-Identifier: GPL-2.0-or-later
// ProgressBar: terminal and log forms.
#include "progress_bar.hpp"

#include <algorithm>

namespace rfbsim::report {

namespace {

constexpr std::size_t kBarWidth = 30;  // characters between the brackets

}  // namespace

ProgressBar::ProgressBar(std::size_t total, bool terminal, std::size_t quiet_up_to, double quiet_seconds)
    : total_(total), terminal_(terminal), quiet_up_to_(quiet_up_to), quiet_seconds_(quiet_seconds) {}

std::string ProgressBar::step(std::size_t done, double elapsed) {
  if (total_ == 0) return "";
  done = std::min(done, total_);
  if (!shown_ && total_ <= quiet_up_to_ && elapsed <= quiet_seconds_) return "";
  const std::string count = std::to_string(done) + "/" + std::to_string(total_) + " sessions";

  if (terminal_) {
    const std::size_t filled = done * kBarWidth / total_;
    const std::string line = "[" + std::string(filled, '#') + std::string(kBarWidth - filled, '.') + "] " + count;
    if (shown_ && line == last_line_) return "";
    shown_ = true;
    last_line_ = line;
    return "\r" + line;
  }
  // A log gets a line when a new tenth is reached (and the first time it shows at all).
  const std::size_t tenth = done * 10 / total_;
  if (shown_ && tenth <= last_tenth_) return "";
  shown_ = true;
  last_tenth_ = tenth;
  return count + " (" + std::to_string(tenth * 10) + " %)";
}

std::string ProgressBar::finish() const { return terminal_ && shown_ ? "\n" : ""; }

}  // namespace rfbsim::report
