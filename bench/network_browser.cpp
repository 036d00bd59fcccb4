// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's browser rows (see network_browser.hpp).
#include "network_browser.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include "network_report.hpp"
#include "sim_process.hpp"

namespace rfbsim::bench {

namespace {

constexpr const char* kResultMarker = "BENCH_RESULT ";
constexpr const char* kErrorMarker = "BENCH_ERROR ";

// The number after `"key":` in a flat JSON text; NaN when absent.
double field(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  if (at == std::string::npos) return kNaN;
  const char* text = json.c_str() + at + key.size() + 3;
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  return end == text ? kNaN : value;
}

// The numbers of the array after `"key":[`.
std::vector<double> array_field(const std::string& json, const std::string& key) {
  std::vector<double> out;
  const auto at = json.find("\"" + key + "\":[");
  if (at == std::string::npos) return out;
  const char* text = json.c_str() + at + key.size() + 4;
  while (*text != ']' && *text != '\0') {
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    if (end == text) break;
    out.push_back(value);
    text = end;
    if (*text == ',') ++text;
  }
  return out;
}

// The line of `output` that starts with `marker`, without it; "" when none.
std::string line_after(const std::string& output, const std::string& marker) {
  const auto at = output.find(marker);
  if (at == std::string::npos) return "";
  const auto end = output.find('\n', at);
  return output.substr(at + marker.size(), end == std::string::npos ? std::string::npos : end - at - marker.size());
}

BrowserRow run_browser(const SimSettings& settings, const std::string& source_dir, const std::string& codec, int rtt,
                       std::chrono::seconds warm_up, std::chrono::seconds measure, int presses, double threshold) {
  BrowserRow row;
  row.codec = codec;
  row.rtt_ms = rtt;
  const auto path = open_path(PathKind::kDirect, settings, codec, test::link_profile(std::chrono::milliseconds(rtt)));
  StreamSampler sampler(*path);
  const std::string script = (std::filesystem::path(source_dir) / "bench" / "bench_network_browser.mjs").string();
  const std::vector<std::string> args = {
      script, "--url", "http://127.0.0.1:" + std::to_string(path->client_port()) + "/", "--web-dir",
      (std::filesystem::path(source_dir) / "web").string(), "--warm-up-ms", std::to_string(warm_up.count() * 1000),
      "--measure-ms", std::to_string(measure.count() * 1000), "--presses", std::to_string(presses), "--threshold",
      fixed(threshold, 1), "--rtt-ms", std::to_string(rtt)};
  const auto limit = warm_up + measure * 3 + std::chrono::seconds(90);
  const test::ExitResult exit = test::run_to_exit(settings.node, args, limit);
  row.samples = sampler.finish();
  const std::string result = line_after(exit.output, kResultMarker);
  if (result.empty()) {
    const std::string error = line_after(exit.output, kErrorMarker);
    row.error = !error.empty() ? error.substr(0, 300)
                               : "no result from node (status " + std::to_string(exit.status) + "): " +
                                     exit.output.substr(exit.output.size() > 300 ? exit.output.size() - 300 : 0);
    return row;
  }
  row.seconds = field(result, "seconds");
  row.page_fps = field(result, "fps");
  row.page_mbit = field(result, "mbit");
  row.presses = static_cast<int>(field(result, "presses"));
  row.timeouts = static_cast<int>(field(result, "timeouts"));
  row.latencies_ms = array_field(result, "latencies");
  return row;
}

}  // namespace

std::vector<BrowserRow> run_browser_rows(const SimSettings& settings, const std::string& source_dir,
                                         const std::vector<int>& rtts, std::chrono::seconds warm_up,
                                         std::chrono::seconds measure, int presses, double threshold) {
  std::vector<BrowserRow> rows;
  for (const std::string codec : {"jpeg", "h264"}) {
    for (const int rtt : rtts) {
      std::fprintf(stderr, "bench_network: browser, --codec %s, RTT %d ms ...\n", codec.c_str(), rtt);
      try {
        rows.push_back(run_browser(settings, source_dir, codec, rtt, warm_up, measure, presses, threshold));
      } catch (const std::exception& error) {
        BrowserRow failed;
        failed.codec = codec;
        failed.rtt_ms = rtt;
        failed.error = error.what();
        rows.push_back(std::move(failed));
      }
      if (!rows.back().error.empty()) std::fprintf(stderr, "bench_network: failed: %s\n", rows.back().error.c_str());
    }
  }
  return rows;
}

void print_browser_rows(const std::vector<BrowserRow>& rows) {
  Table table({"--codec", "RTT ms", "page fps", "fps / fps at 0", "page Mbit/s", "key p50 ms", "key p95 ms",
               "presses (timed out)", "server fps p50", "server RTT p50", "server chose"},
              1);
  double base_fps = kNaN;
  std::string base_codec;
  for (const BrowserRow& row : rows) {
    std::vector<std::string> cells{row.codec, std::to_string(row.rtt_ms)};
    if (!row.error.empty()) {
      cells.push_back("failed: " + row.error);
      table.add_row(std::move(cells));
      continue;
    }
    if (row.rtt_ms == 0) {
      base_fps = row.page_fps;
      base_codec = row.codec;
    }
    const double ratio = base_codec == row.codec ? row.page_fps / base_fps : kNaN;
    std::vector<double> server_fps, server_rtt;
    std::string chose = "-";
    for (const StreamSample& s : row.samples) {
      if (!std::isnan(s.fps) && s.fps > 0) server_fps.push_back(s.fps);
      if (!std::isnan(s.last_rtt_ms)) server_rtt.push_back(s.last_rtt_ms);
      if (s.encoding.empty()) continue;
      chose = s.encoding;
      if (s.encoding == "tight" && !std::isnan(s.quality)) chose += " q" + fixed(s.quality, 0);
    }
    const auto text = [](double v, int d) { return std::isnan(v) ? std::string("-") : fixed(v, d); };
    cells.insert(cells.end(), {fixed(row.page_fps, 1), text(ratio, 2), fixed(row.page_mbit, 2),
                               text(quantile(row.latencies_ms, 0.5), 0), text(quantile(row.latencies_ms, 0.95), 0),
                               std::to_string(row.presses) + " (" + std::to_string(row.timeouts) + ")",
                               text(quantile(server_fps, 0.5), 1), text(quantile(server_rtt, 0.5), 0), chose});
    table.add_row(std::move(cells));
  }
  table.print();
}

}  // namespace rfbsim::bench
