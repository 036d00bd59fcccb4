// SPDX-License-Identifier: GPL-2.0-or-later
// One bench_network cell: a client watching the warehouse through an emulated link while the participant walks,
// measured for frame rate, bytes, key-to-picture latency and queueing.
//
// The participant (this process, through the client):
//   - holds the walk key (default 'w') from the first picture to the end, so the view keeps changing;
//   - presses the turn key (default 'd') for `turn_hold` about once per `press_every`, at a random phase
//     (0.8..1.2 of the interval after the previous press, so presses land at every phase of the 30 fps frame
//     clock), but never before the previous turn has shown in full (its detection + turn_hold + 200 ms);
// and the cell is judged, after an unmeasured warm-up in which the same happens (the congestion control
// converges), over a window of `measure` that is stretched, if need be, until `presses` presses were made in it:
//   fps        complete updates at the client per second of the window;
//   Mbit/s     bytes the emulator delivered to the client over the window (RFB payload, or WebSocket frames
//              on the manager path);
//   latency    per press: from sending the key down to the arrival of the first update, one RTT or more after
//              the press, whose picture differs from the reference by a mean absolute difference above
//              `threshold`; the reference is the client's picture at the press, moved up to the last picture
//              that arrived within one RTT of it (no picture can show a press sooner, and the walk goes on
//              meanwhile). Turning swings most of the view; walking and the crowd change far less between two
//              pictures a few frames apart (see bench_network's --mad-trace). None within `press_timeout` =
//              a timed-out press;
//   queueing   the emulator's longest time from a chunk being read to it leaving the bottleneck queue;
//   stalls     the longest gap between two updates;
//   the server's own report of the stream, sampled every 500 ms on a thread of its own.
#pragma once

#include <chrono>
#include <cstdint>
#include <random>
#include <vector>

#include "network_clients.hpp"
#include "network_paths.hpp"

namespace rfbsim::bench {

/// How a cell runs; the defaults are bench_network's.
struct CellPlan {
  std::chrono::milliseconds warm_up{3000};        ///< unmeasured, from the first picture on
  std::chrono::milliseconds measure{10000};       ///< the measured window, at least
  int presses = 10;                               ///< presses made in the window, at least
  std::chrono::milliseconds press_every{1000};    ///< mean interval between presses
  std::chrono::milliseconds turn_hold{300};       ///< how long each press holds the turn key
  std::chrono::milliseconds press_timeout{3000};  ///< a press with no visible change this long timed out
  double threshold = 12.0;                        ///< mean absolute difference (0..255) that counts as visible
  /// The link's round trip: no picture arriving sooner after a press can show it, so those are never judged;
  /// each of them becomes the press's reference instead (the walk moves on meanwhile, the turn cannot yet).
  std::chrono::milliseconds rtt{0};
  std::uint32_t walk_key = 'w';
  std::uint32_t turn_key = 'd';
  bool trace = false;  ///< keep each press's (ms after the press, MAD) series, whatever the threshold
};

/// One press in the measured window.
struct PressResult {
  double at_s = 0;        ///< when the key went down, seconds after the window began
  double latency_ms = 0;  ///< press to the first visible update; NaN when it timed out
  /// With CellPlan::trace: (ms after the press, MAD against the reference) per update judged; updates within
  /// the RTT (not judged, they become the reference) as (ms, -1).
  std::vector<std::pair<double, double>> trace;
};

/// What one cell measured.
struct CellResult {
  double seconds = 0;                 ///< length of the measured window
  std::uint64_t updates = 0;          ///< complete updates that arrived in it
  std::uint64_t bytes_down = 0;       ///< bytes the emulator delivered to the client in it
  std::uint64_t h264_bytes = 0;       ///< H.264 payload bytes in it (h264 client)
  std::uint64_t decode_errors = 0;    ///< H.264 pictures that failed, whole cell
  double max_queue_delay_ms = 0;      ///< the emulator's longest bottleneck queueing in the window (down)
  double max_gap_ms = 0;              ///< longest time between two updates in the window
  std::vector<double> arrivals_s;     ///< each update's arrival, seconds after the window began
  std::vector<PressResult> presses;   ///< every press made in the window
  std::vector<StreamSample> samples;  ///< the server's reports taken in the window
  [[nodiscard]] double fps() const { return seconds > 0 ? static_cast<double>(updates) / seconds : 0.0; }
  [[nodiscard]] double mbit() const { return seconds > 0 ? static_cast<double>(bytes_down) * 8e-6 / seconds : 0.0; }
  /// The presses' latencies (timed-out ones left out), optionally only those made in [from_s, to_s).
  [[nodiscard]] std::vector<double> latencies(double from_s = -1e300, double to_s = 1e300) const;
  /// Presses that timed out.
  [[nodiscard]] int timeouts() const;
};

/// Runs one cell on a client already connected (its first update in) through `path`. Throws
/// std::runtime_error when the connection drops.
CellResult run_cell(NetClient& client, CellPath& path, const CellPlan& plan, std::mt19937& rng);

}  // namespace rfbsim::bench
