// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's tables: the matrix per path, the frame-rate ratios against RTT, the long run's halves.
#pragma once

#include <string>
#include <vector>

#include "network_cells.hpp"

namespace rfbsim::bench {

/// One measured matrix cell with its coordinates.
struct MatrixCell {
  PathKind path = PathKind::kDirect;
  int rtt_ms = 0;
  double cap_mbit = 0;  ///< 0 = no cap
  ClientKind client = ClientKind::kFbur;
  CellResult result;
  std::string error;  ///< why the cell failed ("" when it ran)
  std::string load;   ///< the 1-minute load average when it ended (other work skews every number)
};

/// The q-quantile (0..1) of `samples`, interpolating between closest ranks; NaN when empty.
double quantile(std::vector<double> samples, double q);

/// "none" for 0, else the cap in Mbit/s without trailing zeros.
std::string cap_text(double cap_mbit);

/// Prints the matrix table of `path` (its cells in the order given).
void print_matrix(const std::vector<MatrixCell>& cells, PathKind path);

/// Prints fps at each RTT over fps at RTT 0 for every (path, client, cap) with an RTT-0 cell, and the issue's
/// targets (>= 0.9 at 100 ms, >= 0.8 at 200 ms).
void print_ratios(const std::vector<MatrixCell>& cells);

/// Prints key-to-picture p50 against RTT per (path, client) at each cap, and H.264's bytes against JPEG's (cu).
void print_latency_and_bytes(const std::vector<MatrixCell>& cells);

/// One long run (the growing-lag check).
struct LongRun {
  PathKind path = PathKind::kDirect;
  ClientKind client = ClientKind::kCu;
  CellResult result;
  std::string error;
};

/// Prints the long runs: latency p50 / p90, fps and presses in the first and the last `part_s` seconds.
void print_long_runs(const std::vector<LongRun>& runs, int rtt_ms, double cap_mbit, double part_s);

/// Prints each press's MAD series (ms after the press, MAD) for threshold calibration.
void print_traces(const std::string& title, const CellResult& result);

}  // namespace rfbsim::bench
