// SPDX-License-Identifier: GPL-2.0-or-later
// The ready pipe's "stream" line: how the participant's picture stream is doing, written by sim_rfb about once a
// second while someone watches and once when the last viewer leaves, read by sim_manager (admin page, /api,
// /metrics):
//
//   stream codec=tight rtt_ms=12.5 fps=29.8 quality=80 clients=1
//   stream codec=tight rtt_ms=3.1 fps=30.0 quality=42 requested=42 clients=1
//   stream clients=0
//
// Space-separated key=value pairs after the word "stream", in this order:
//   codec    what the participant gets: "tight", "zrle", "hextile", "raw", "h264", ... (1..16 lower-case letters
//            and digits; left out when the server names none)
//   rtt_ms   the latest round trip measured with fences, ms, one decimal; -1 while none was measured
//   fps      updates per second over about the last second, one decimal
//   quality  the JPEG quality in use 1..100 (Tight), or the top one (H.264); left out where none
//            applies (ZRLE, Hextile, Raw and the other lossless encodings)
//   requested  the JPEG quality 1..100 the participant's viewer asked for (a Tight quality level, e.g.
//            TigerVNC's -QualityLevel or noVNC's ?quality=), which caps quality; left out when it asked none
//   clients  how many viewers are connected; with 0 no other key follows
// Readers ignore keys they do not know: later versions may add some. docs/deployment.md describes it too.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace rfbsim::contract {

/// The bounds of the line's values: the writer clamps to them and the parser refuses anything outside.
constexpr double kMaxStreamRttMs = 600000;  // ten minutes
constexpr double kMaxStreamFps = 1000;      // beyond any display
constexpr int kMaxStreamQuality = 100;
constexpr int kMaxStreamClients = 9999;     // four digits keep the line short

/// One stream line: what the participant's picture stream is like now. Unknown values stay unset.
struct StreamReport {
  int clients = 0;                ///< viewers connected to the session (participant and watchers)
  std::string codec;              ///< "tight", "h264", ... (see is_codec_name); "" = not said
  std::optional<double> rtt_ms;   ///< the latest round trip, ms (0..600000); unset = not measured (-1 on the line)
  std::optional<double> fps;      ///< updates per second over about the last second (0..1000)
  std::optional<int> quality;     ///< JPEG quality in use (0..100); unset where none applies (ZRLE, Raw ...)
  std::optional<int> requested;   ///< JPEG quality the viewer asked for (0..100); unset = it asked none
};

/// The outcome of parsing a line: a report, or what is wrong with it.
struct StreamParse {
  std::optional<StreamReport> report;
  std::string error;  ///< empty on success
};

/// True for a codec's name as the line carries it: 1 to 16 lower-case letters and digits, so that it is safe
/// as a Prometheus label value, in JSON and on a page as it is.
bool is_codec_name(std::string_view name);

/// The line for `report`, newline included; under 100 bytes, so that one write() of it to a pipe is atomic.
/// clients 0 gives "stream clients=0\n". Otherwise codec is left out when it is not a codec name, rtt_ms is -1
/// when unset, fps is 0 when unset, quality and requested are left out when unset, and every number is clamped to its bound (a non-finite one
/// to 0).
std::string stream_line(const StreamReport& report);

/// Whether `line` (without its newline) is a stream line at all: the word "stream", alone or before a space.
bool is_stream_line(std::string_view line);

/// Parses a stream line: "stream" then space-separated key=value pairs. `clients` is required; `codec`,
/// `rtt_ms`, `fps`, `quality` and `requested` are optional; keys this version does not know are ignored (a newer sim_rfb may
/// add some). A pair without '=', a key given twice, or a value out of its range or not a plain number is an
/// error naming it, and nothing of the line is taken. Never throws.
StreamParse parse_stream_line(std::string_view line);

}  // namespace rfbsim::contract
