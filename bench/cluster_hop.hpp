// SPDX-License-Identifier: GPL-2.0-or-later
// bench_cluster (b): the balancer's own hop. The same requests and the same WebSocket frames, straight to a
// manager and through HAProxy, interleaved so that both see the same machine load.
#pragma once

#include <vector>

#include "cluster_under_test.hpp"

namespace rfbsim::bench {

/// How many samples of each kind, per path.
struct HopOptions {
  int requests = 1000;  ///< GET /healthz, each on a new connection
  int frames = 400;     ///< RFB fence round trips over the session's WebSocket (in blocks of 100)
};

/// Round-trip times in milliseconds, per path.
struct HopSamples {
  std::vector<double> request_direct, request_proxied;  ///< connect, GET /healthz, whole answer
  std::vector<double> frame_direct, frame_proxied;      ///< a Fence request to its answer, through the relay
};

/// Measures both on `cluster` (which must have a free slot for one session).
HopSamples measure_hop(const test::ClusterUnderTest& cluster, const HopOptions& options);

}  // namespace rfbsim::bench
