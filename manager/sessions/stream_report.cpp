// SPDX-License-Identifier: GPL-2.0-or-later
// Stream lines from sim_rfb's ready pipe.
#include "sessions/stream_report.hpp"

#include <charconv>
#include <cmath>
#include <set>

namespace rfbsim::manager {

namespace {

constexpr std::string_view kWord = "stream";

// A plain decimal number such as "12", "12.5" or "-1" (no exponent, no sign other than a leading '-', no
// "inf" or "nan") within low..high.
std::optional<double> decimal(std::string_view text, double low, double high) {
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
std::optional<int> whole(std::string_view text, int low, int high) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || text.front() == '-' || ec != std::errc() || ptr != end || value < low || value > high) {
    return std::nullopt;
  }
  return value;
}

// A codec's name: safe as a Prometheus label value, in JSON and on a page as it is.
bool is_codec_name(std::string_view text) {
  if (text.empty() || text.size() > 16) return false;
  for (const char c : text) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'))) return false;
  }
  return true;
}

// Applies one known key's value to `report`; false when the value is bad. Unknown keys are not passed here.
bool apply(std::string_view key, std::string_view value, StreamReport& report) {
  if (key == "clients") {
    const auto clients = whole(value, 0, 10000);
    if (clients) report.clients = *clients;
    return clients.has_value();
  }
  if (key == "codec") {
    if (!is_codec_name(value)) return false;
    report.codec = std::string(value);
    return true;
  }
  if (key == "rtt_ms") {
    const auto rtt = decimal(value, -1, 600000);
    if (!rtt || (*rtt < 0 && *rtt != -1)) return false;  // -1 alone means "not measured"
    if (*rtt >= 0) report.rtt_ms = *rtt;
    return true;
  }
  if (key == "fps") {
    report.fps = decimal(value, 0, 1000);
    return report.fps.has_value();
  }
  // quality
  report.quality = whole(value, 0, 100);
  return report.quality.has_value();
}

}  // namespace

bool is_stream_line(std::string_view line) {
  return line.substr(0, kWord.size()) == kWord && (line.size() == kWord.size() || line[kWord.size()] == ' ');
}

StreamParse parse_stream_line(std::string_view line) {
  StreamParse out;
  if (!is_stream_line(line)) {
    out.error = "not a stream line";
    return out;
  }
  static const std::set<std::string_view> known = {"clients", "codec", "rtt_ms", "fps", "quality"};
  StreamReport report;
  std::set<std::string_view> seen;
  // Pairs are separated by spaces; runs of spaces and a trailing carriage return are let pass.
  std::string_view rest = line.substr(kWord.size());
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
    if (!apply(key, value, report)) {
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

}  // namespace rfbsim::manager
