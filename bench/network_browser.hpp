// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's browser rows: the participant page (noVNC 1.7) in headless Chromium through a LinkEmulator,
// run by bench_network_browser.mjs (node, playwright-core from web/node_modules, Debian's /usr/bin/chromium).
// Per codec (sim_rfb --codec jpeg, then h264) and RTT (no cap): a fresh sim_rfb serving its own page, the
// emulator in front of it, the script walking and turning and counting the pictures the page shows; meanwhile
// sim_rfb's /status.json says which encoding it chose and the frame rate it sent.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "network_paths.hpp"

namespace rfbsim::bench {

/// One browser run.
struct BrowserRow {
  std::string codec;  ///< sim_rfb --codec
  int rtt_ms = 0;
  double seconds = 0;        ///< the page's measured window
  double page_fps = 0;       ///< pictures the page showed per second
  double page_mbit = 0;      ///< WebSocket bytes the page received, Mbit/s
  std::vector<double> latencies_ms;  ///< key-to-picture, as the page saw it
  int presses = 0;
  int timeouts = 0;
  std::vector<StreamSample> samples;  ///< sim_rfb's reports during the run
  std::string error;                  ///< why the run failed ("" when it ran)
};

/// Runs the browser rows: codecs jpeg and h264, each at every RTT in `rtts` without a cap, `warm_up` then at
/// least `measure` and `presses` presses each. `source_dir` is the repository (bench/ and web/ under it).
std::vector<BrowserRow> run_browser_rows(const SimSettings& settings, const std::string& source_dir,
                                         const std::vector<int>& rtts, std::chrono::seconds warm_up,
                                         std::chrono::seconds measure, int presses, double threshold);

/// Prints the browser table.
void print_browser_rows(const std::vector<BrowserRow>& rows);

}  // namespace rfbsim::bench
