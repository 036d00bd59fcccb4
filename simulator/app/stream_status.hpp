// SPDX-License-Identifier: GPL-2.0-or-later
// How sim_rfb reports its viewers' streams (codec, round trip, frame rate, quality): as the "streams" array of
// /status.json, and as the "stream" line on the ready pipe that sim_manager reads. Pure text: the caller asks
// the server for rfbsim::Server::client_streams() and writes the result where it belongs.
//
// The ready pipe's line ("stream codec=tight rtt_ms=12.5 fps=29.8 quality=80 clients=1", or "stream clients=0"
// when the last viewer leaves) is the contract's (contract/stream_line.hpp has its keys); this file picks the
// participant's stream (main_stream()) and fills it in.
#pragma once

#include <string>
#include <vector>

#include "rfbsim/server.hpp"

namespace rfbsim::sim {

/// The participant's stream among `streams`: the one with the most updates sent (the lowest id on a tie), since a
/// researcher watching joins later and a client that stalled gets fewer; null when `streams` is empty.
const rfbsim::ClientStreamStatus* main_stream(const std::vector<rfbsim::ClientStreamStatus>& streams);

/// The JSON array for /status.json's "streams": one object per client, in the order given, with the keys id,
/// encoding, continuous_updates, fence, base_rtt_ms, last_rtt_ms (both null while not measured), window_bytes,
/// in_flight_bytes, updates_sent, updates_held, update_requests, quality, quality_level, requested_quality and
/// requested_quality_level (these four only where a JPEG quality applies; the requested ones null when the client
/// named none), compress_level, delivery_mbit and fps.
std::string streams_json(const std::vector<rfbsim::ClientStreamStatus>& streams);

/// The ready pipe's stream line for `streams` (rfbsim::contract::stream_line of the participant's stream and the
/// number of viewers), newline included; under 100 bytes, so that one write() of it to a pipe is atomic.
std::string stream_line(const std::vector<rfbsim::ClientStreamStatus>& streams);

}  // namespace rfbsim::sim
