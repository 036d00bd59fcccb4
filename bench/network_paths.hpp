// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's two paths from a participant's viewer to the simulator, each with the emulated internet
// link where a participant's would be:
//   direct   client -> LinkEmulator -> sim_rfb (its own port: RFB, page and /status.json);
//   manager  client -> WsRfbBridge -> LinkEmulator -> sim_manager (/s/<token>/ws, the relay) -> sim_rfb.
// The bridge stands in for the browser's WebSocket, so it sits on the participant's side of the link.
// A path owns every process and relay it started and stops them on destruction (emulator and bridge first).
#pragma once

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "link_emulator.hpp"

namespace rfbsim::bench {

/// Not a number: what a measure reads where nothing was measured.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Which path a cell runs.
enum class PathKind { kDirect, kManager };

/// "direct" or "manager".
const char* path_name(PathKind kind);
/// The kind named `name`; throws std::invalid_argument for another name.
PathKind parse_path(const std::string& name);

/// How the simulator runs in every cell (sim_rfb directly, or as sim_manager's session).
struct SimSettings {
  std::string sim;                       ///< the sim_rfb binary (direct path)
  std::string manager;                   ///< the sim_manager binary (manager path; it starts its own sim_rfb)
  std::string scenario = "warehouse";    ///< scenario name
  int fps = 30;                          ///< sim_rfb --fps
  std::uint64_t seed = 7;                ///< sim_rfb --seed: the same crowd in every cell
  std::string avatar_start;              ///< sim_rfb --avatar-start ("" = the scenario's)
  std::string log;                       ///< children's stderr is appended here
  std::string node = "/usr/bin/node";    ///< node, for the browser rows
  std::vector<std::string> extra_args;   ///< more sim_rfb flags (direct path), e.g. another --web-root
};

/// What the server reported about the (only) client's stream at one moment; NaN / "" for what it did not say.
struct StreamSample {
  Clock::time_point at;
  std::string encoding;        ///< "tight" or "h264"
  double base_rtt_ms = kNaN;    ///< lowest round trip through fences so far (direct only)
  double last_rtt_ms = kNaN;    ///< latest round trip
  double window_bytes = kNaN;   ///< congestion window (direct only)
  double updates_held = kNaN;   ///< frames held back because the link was full, so far (direct only)
  double quality = kNaN;        ///< JPEG quality in use (Tight), or the configured one (H.264)
  double quality_level = kNaN;  ///< the adaptive ladder's level (0 = top) (direct only)
  double fps = kNaN;            ///< updates per second lately
};

/// A running path for one cell.
class CellPath {
 public:
  virtual ~CellPath() = default;
  /// The loopback port where the cell's raw-RFB client connects.
  [[nodiscard]] virtual int client_port() const = 0;
  /// The emulated link (stats, peaks).
  [[nodiscard]] virtual test::LinkEmulator& link() = 0;
  /// The participant page through the emulated link, for a browser: sim_rfb's own page (direct), or the
  /// session's page under the manager.
  [[nodiscard]] virtual std::string page_url() const = 0;
  /// One look at the server's report of its client's stream (sim_rfb's /status.json, or sim_manager's
  /// /metrics); nullopt when no stream is reported. Safe from any thread; a few ms.
  [[nodiscard]] virtual std::optional<StreamSample> sample() const = 0;
};

/// Polls a path's stream report (CellPath::sample) every 500 ms on a thread of its own while it lives.
/// The path must outlive it.
class StreamSampler {
 public:
  explicit StreamSampler(const CellPath& path);
  /// Stops the thread (finish() without a result).
  ~StreamSampler();
  StreamSampler(const StreamSampler&) = delete;
  StreamSampler& operator=(const StreamSampler&) = delete;
  /// Stops the thread and returns the samples taken at or after `from`, oldest first.
  std::vector<StreamSample> finish(Clock::time_point from = {});

 private:
  void loop(const CellPath& path);
  std::mutex mutex_;
  std::vector<StreamSample> samples_;
  std::atomic<bool> stop_{false};
  std::thread thread_;  // last: starts once the rest is there
};

/// Starts the path: the simulator with `--codec codec` (a manager-path session through its own sim_manager),
/// and the emulator with `profile`. Throws std::runtime_error when a process does not start or the session
/// never runs.
std::unique_ptr<CellPath> open_path(PathKind kind, const SimSettings& settings, const std::string& codec,
                                    const test::LinkProfile& profile);

/// The command-line arguments sim_rfb gets in every cell beyond the port: scenario, fps, seed, avatar start.
std::vector<std::string> sim_args(const SimSettings& settings, const std::string& codec);

/// Parses sim_rfb's /status.json body: the first entry of "streams"; nullopt when the array is empty.
std::optional<StreamSample> parse_status_stream(const std::string& json);

}  // namespace rfbsim::bench
