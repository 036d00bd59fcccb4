// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's browser rows: a browser client through a LinkEmulator, run by bench_network_browser.mjs (node,
// with playwright-core driving Debian's /usr/bin/chromium, or puppeteer-core driving Debian's firefox-esr over
// WebDriver BiDi, both from web/node_modules). The clients: the participant page (noVNC 1.7) in Chromium with
// sim_rfb's default --codec auto, then with --codec jpeg and --codec h264; the page in Firefox with the default
// (and with h264, and through a sim_manager session of its own); and Debian's stock noVNC 1.3 page (JPEG only:
// it offers no H.264) in Chromium with the default. Per client and RTT (no cap unless asked): a fresh sim_rfb
// serving the page, the emulator in front of it, the script walking and turning and counting the pictures the
// page shows; meanwhile the server's report says which encoding it chose, at which quality, and the frame rate
// it sent.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "network_paths.hpp"

namespace rfbsim::bench {

/// One kind of browser client.
struct BrowserClient {
  std::string name;     ///< the row's name and --browser-clients item: auto, jpeg, h264, firefox, firefox-h264, firefox-manager, novnc13
  std::string browser;  ///< chromium or firefox
  std::string page;     ///< bundled (web/, served by sim_rfb) or novnc13 (Debian's /usr/share/novnc)
  std::string codec;    ///< sim_rfb --codec
  PathKind path = PathKind::kDirect;  ///< sim_rfb alone, or a session of its own sim_manager
};

/// Every browser client, default first; parse_browser_client() reads a name.
std::vector<BrowserClient> browser_clients();
BrowserClient parse_browser_client(const std::string& name);

/// One browser run.
struct BrowserRow {
  BrowserClient client;
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

/// How the browser rows run.
struct BrowserPlan {
  std::vector<BrowserClient> clients;
  std::vector<int> rtts;
  double cap_mbit = 0;    ///< the link's cap in both directions (0: none)
  std::chrono::seconds warm_up{3};
  std::chrono::seconds measure{10};  ///< at least this, and `presses` presses
  int presses = 10;
  double threshold = 12;
  bool trace = false;  ///< print sim_rfb's stream reports of each run, one line each
};

/// Runs the browser rows, client by client, each at every RTT. `source_dir` is the repository (bench/ and web/).
std::vector<BrowserRow> run_browser_rows(const SimSettings& settings, const std::string& source_dir,
                                         const BrowserPlan& plan);

/// Prints the browser table.
void print_browser_rows(const std::vector<BrowserRow>& rows);

}  // namespace rfbsim::bench
