// SPDX-License-Identifier: GPL-2.0-or-later
// The viewers' streams as /status.json's "streams" array and as the ready pipe's "stream" line.
#include "app/stream_status.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "contract/stream_line.hpp"

namespace rfbsim::sim {

namespace {

// A codec's name as the JSON carries it (the stream line's rule); "" for anything else, which is then left out
// rather than passed on to sim_manager's labels and pages.
std::string clean_name(const std::string& name) { return contract::is_codec_name(name) ? name : ""; }

// A number for JSON with `decimals` decimals; null when it is not finite (never expected, never invalid JSON).
std::string json_number(double value, int decimals) {
  if (!std::isfinite(value)) return "null";
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

// A round trip for JSON: null while not measured (the library says -1).
std::string json_rtt(double ms) { return ms < 0 ? "null" : json_number(ms, 1); }

// A level a client asked for, for JSON: null below `lowest` (the library's "none asked").
std::string json_level(int level, int lowest) { return level < lowest ? "null" : std::to_string(level); }

}  // namespace

const rfbsim::ClientStreamStatus* main_stream(const std::vector<rfbsim::ClientStreamStatus>& streams) {
  const rfbsim::ClientStreamStatus* best = nullptr;
  for (const rfbsim::ClientStreamStatus& stream : streams) {
    if (best == nullptr || stream.updates_sent > best->updates_sent ||
        (stream.updates_sent == best->updates_sent && stream.id < best->id)) {
      best = &stream;
    }
  }
  return best;
}

std::string streams_json(const std::vector<rfbsim::ClientStreamStatus>& streams) {
  std::string json = "[";
  for (const rfbsim::ClientStreamStatus& s : streams) {
    if (json.size() > 1) json += ",";
    const std::string encoding = clean_name(s.encoding);
    json += "{\"id\":" + std::to_string(s.id) +
            ",\"encoding\":" + (encoding.empty() ? std::string("null") : "\"" + encoding + "\"") +
            ",\"continuous_updates\":" + (s.continuous_updates ? "true" : "false") +
            ",\"fence\":" + (s.fence ? "true" : "false") + ",\"base_rtt_ms\":" + json_rtt(s.base_rtt_ms) +
            ",\"last_rtt_ms\":" + json_rtt(s.last_rtt_ms) + ",\"window_bytes\":" + std::to_string(s.window_bytes) +
            ",\"in_flight_bytes\":" + std::to_string(s.in_flight_bytes) +
            ",\"updates_sent\":" + std::to_string(s.updates_sent) +
            ",\"updates_held\":" + std::to_string(s.updates_held) +
            ",\"update_requests\":" + std::to_string(s.update_requests) +
            // A quality only where one applies (Tight's JPEG, H.264): ZRLE, Hextile and Raw are lossless.
            // What the client asked for beside it: null when it named no quality (the server's then applies).
            (s.quality > 0 ? ",\"quality\":" + std::to_string(s.quality) +
                                 ",\"quality_level\":" + std::to_string(s.quality_level) +
                                 ",\"requested_quality\":" + json_level(s.requested_quality, 1) +
                                 ",\"requested_quality_level\":" + json_level(s.requested_quality_level, 0)
                           : std::string()) +
            ",\"compress_level\":" + std::to_string(s.compress_level) +
            ",\"delivery_mbit\":" + json_number(s.delivery_mbit, 2) + ",\"fps\":" + json_number(s.fps, 1) + "}";
  }
  return json + "]";
}

std::string stream_line(const std::vector<rfbsim::ClientStreamStatus>& streams) {
  contract::StreamReport report;
  const rfbsim::ClientStreamStatus* participant = main_stream(streams);
  if (participant == nullptr) return contract::stream_line(report);  // nobody watches: "stream clients=0"
  // The writer bounds every value and drops a codec name that is not one.
  report.clients = static_cast<int>(std::min<std::size_t>(streams.size(), contract::kMaxStreamClients));
  report.codec = participant->encoding;
  if (participant->last_rtt_ms >= 0) report.rtt_ms = participant->last_rtt_ms;  // the library says -1 until measured
  report.fps = participant->fps;
  if (participant->quality > 0) report.quality = participant->quality;
  if (participant->quality > 0 && participant->requested_quality > 0) report.requested = participant->requested_quality;
  return contract::stream_line(report);
}

}  // namespace rfbsim::sim
