// SPDX-License-Identifier: GPL-2.0-or-later
// The participant's stream as sim_rfb reports it on the ready pipe, about once a second while someone watches:
//
//   stream codec=tight rtt_ms=12.5 fps=29.8 quality=80 clients=1
//   stream clients=0
//
// Pure: parsing only, for the supervisor (which keeps the latest per session) and its tests. The format is
// sim_rfb's (simulator/app/stream_status.hpp) and docs/deployment.md describes it.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace rfbsim::manager {

/// One stream line: what the participant's picture stream is like now. Unknown values stay unset.
struct StreamReport {
  int clients = 0;                ///< viewers connected to the session (participant and watchers)
  std::string codec;              ///< "tight", "h264", ... (1..16 lower-case letters and digits); "" = not said
  std::optional<double> rtt_ms;   ///< the latest round trip, ms (0..600000); unset = not measured (-1 on the line)
  std::optional<double> fps;      ///< updates per second over about the last second (0..1000)
  std::optional<int> quality;     ///< JPEG quality in use (0..100)
};

/// The outcome of parsing a line: a report, or what is wrong with it.
struct StreamParse {
  std::optional<StreamReport> report;
  std::string error;  ///< empty on success
};

/// Whether `line` (without its newline) is a stream line at all: the word "stream", alone or before a space.
bool is_stream_line(std::string_view line);

/// Parses a stream line: "stream" then space-separated key=value pairs. `clients` is required; `codec`,
/// `rtt_ms`, `fps` and `quality` are optional; keys this version does not know are ignored (a newer sim_rfb may
/// add some). A pair without '=', a key given twice, or a value out of its range or not a plain number is an
/// error naming it, and nothing of the line is taken. Never throws.
StreamParse parse_stream_line(std::string_view line);

}  // namespace rfbsim::manager
