// SPDX-License-Identifier: GPL-2.0-or-later
// The ready pipe's stream line: its writer and its parser, side by side so that they keep one format.
#include "contract/stream_line.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <set>

namespace rfbsim::contract {

namespace {

constexpr std::string_view kStreamWord = "stream";

// `value` limited to low..high; low when it is not finite.
double stream_clamped(double value, double low, double high) {
  return std::isfinite(value) ? std::clamp(value, low, high) : low;
}

// A plain decimal number such as "12", "12.5" or "-1" (no exponent, no sign other than a leading '-', no
// "inf" or "nan") within low..high.
std::optional<double> stream_decimal(std::string_view text, double low, double high) {
  if (text.empty() || text.size() > 24) return std::nullopt;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (!((c >= '0' && c <= '9') || c == '.' || (c == '-' && i == 0))) return std::nullopt;
  }
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value) || value < low || value > high) return std::nullopt;
  return value;
}

// A whole number of digits within low..high.
std::optional<int> stream_whole(std::string_view text, int low, int high) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || text.front() == '-' || ec != std::errc() || ptr != end || value < low || value > high) {
    return std::nullopt;
  }
  return value;
}

// Applies one known key's value to `report`; false when the value is bad. Unknown keys are not passed here.
bool apply_stream_value(std::string_view key, std::string_view value, StreamReport& report) {
  if (key == "clients") {
    const auto clients = stream_whole(value, 0, kMaxStreamClients);
    if (clients) report.clients = *clients;
    return clients.has_value();
  }
  if (key == "codec") {
    if (!is_codec_name(value)) return false;
    report.codec = std::string(value);
    return true;
  }
  if (key == "rtt_ms") {
    const auto rtt = stream_decimal(value, -1, kMaxStreamRttMs);
    if (!rtt || (*rtt < 0 && *rtt != -1)) return false;  // -1 alone means "not measured"
    if (*rtt >= 0) report.rtt_ms = *rtt;
    return true;
  }
  if (key == "fps") {
    report.fps = stream_decimal(value, 0, kMaxStreamFps);
    return report.fps.has_value();
  }
  if (key == "requested") {
    report.requested = stream_whole(value, 0, kMaxStreamQuality);
    return report.requested.has_value();
  }
  // quality
  report.quality = stream_whole(value, 0, kMaxStreamQuality);
  return report.quality.has_value();
}

}  // namespace

bool is_codec_name(std::string_view name) {
  if (name.empty() || name.size() > 16) return false;
  return std::all_of(name.begin(), name.end(), [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); });
}

std::string stream_line(const StreamReport& report) {
  const int clients = std::clamp(report.clients, 0, kMaxStreamClients);
  if (clients == 0) return "stream clients=0\n";
  // Every value bounded, so that the line stays short.
  std::string line = "stream";
  if (is_codec_name(report.codec)) line += " codec=" + report.codec;
  char rtt[32] = " rtt_ms=-1";
  if (report.rtt_ms) std::snprintf(rtt, sizeof rtt, " rtt_ms=%.1f", stream_clamped(*report.rtt_ms, 0, kMaxStreamRttMs));
  char fps[32];
  std::snprintf(fps, sizeof fps, " fps=%.1f", stream_clamped(report.fps.value_or(0), 0, kMaxStreamFps));
  // A quality only where one applies (a lossless encoding has none).
  char quality[32] = "";
  if (report.quality) {
    std::snprintf(quality, sizeof quality, " quality=%d", std::clamp(*report.quality, 0, kMaxStreamQuality));
  }
  // The viewer's own request, where it made one: 14 bytes at most, so the longest line stays under 100.
  char requested[32] = "";
  if (report.requested) {
    std::snprintf(requested, sizeof requested, " requested=%d", std::clamp(*report.requested, 0, kMaxStreamQuality));
  }
  return line + rtt + fps + quality + requested + " clients=" + std::to_string(clients) + "\n";
}

bool is_stream_line(std::string_view line) {
  return line.substr(0, kStreamWord.size()) == kStreamWord &&
         (line.size() == kStreamWord.size() || line[kStreamWord.size()] == ' ');
}

StreamParse parse_stream_line(std::string_view line) {
  StreamParse out;
  if (!is_stream_line(line)) {
    out.error = "not a stream line";
    return out;
  }
  static const std::set<std::string_view> known = {"clients", "codec", "rtt_ms", "fps", "quality", "requested"};
  StreamReport report;
  std::set<std::string_view> seen;
  // Pairs are separated by spaces; runs of spaces and a trailing carriage return are let pass.
  std::string_view rest = line.substr(kStreamWord.size());
  if (!rest.empty() && rest.back() == '\r') rest.remove_suffix(1);
  while (!rest.empty()) {
    if (rest.front() == ' ') {
      rest.remove_prefix(1);
      continue;
    }
    const std::string_view pair = rest.substr(0, rest.find(' '));
    rest.remove_prefix(pair.size());
    const std::size_t equals = pair.find('=');
    if (equals == std::string_view::npos || equals == 0) {
      out.error = "'" + std::string(pair.substr(0, 32)) + "' is not key=value";
      return out;
    }
    const std::string_view key = pair.substr(0, equals);
    const std::string_view value = pair.substr(equals + 1);
    if (!seen.insert(key).second) {
      out.error = "key '" + std::string(key.substr(0, 32)) + "' given twice";
      return out;
    }
    if (known.count(key) == 0) continue;  // a newer sim_rfb's: ignored
    if (!apply_stream_value(key, value, report)) {
      out.error = "bad value '" + std::string(value.substr(0, 32)) + "' for " + std::string(key);
      return out;
    }
  }
  if (seen.count("clients") == 0) {
    out.error = "no clients=N";
    return out;
  }
  out.report = report;
  return out;
}

}  // namespace rfbsim::contract
