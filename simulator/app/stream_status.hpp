// SPDX-License-Identifier: GPL-2.0-or-later
// How sim_rfb reports its viewers' streams (codec, round trip, frame rate, quality): as the "streams" array of
// /status.json, and as the "stream" line on the ready pipe that sim_manager reads. Pure text: the caller asks
// the server for rfbsim::Server::client_streams() and writes the result where it belongs.
//
// The ready pipe's line, one about every second while someone watches and one when the last viewer leaves:
//
//   stream codec=tight rtt_ms=12.5 fps=29.8 quality=80 clients=1
//   stream clients=0
//
// Space-separated key=value pairs after the word "stream", in this order, describing the participant's stream
// (the client that has had the most updates; see main_stream()):
//   codec    "tight" or "h264" (the stream's encoding; left out when the server names none)
//   rtt_ms   the latest round trip measured with fences, ms, one decimal; -1 while none was measured (a client
//            without Fence support, or before its first answer)
//   fps      updates per second over about the last second, one decimal
//   quality  the JPEG quality in use 1..100 (Tight), or the configured one (H.264)
//   clients  how many viewers are connected; with 0 no other key follows
// Readers must ignore keys they do not know: later versions may add some. docs/deployment.md describes it too.
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
/// in_flight_bytes, updates_sent, updates_held, quality, quality_level, delivery_mbit and fps.
std::string streams_json(const std::vector<rfbsim::ClientStreamStatus>& streams);

/// The ready pipe's stream line for `streams`, newline included (format above); under 100 bytes, so that one
/// write() of it to a pipe is atomic.
std::string stream_line(const std::vector<rfbsim::ClientStreamStatus>& streams);

}  // namespace rfbsim::sim
