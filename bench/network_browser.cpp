// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's browser rows (see network_browser.hpp).
#include "network_browser.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "manager_process.hpp"
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

// Debian's novnc package: noVNC 1.3's own page, served by sim_rfb in place of ours.
constexpr const char* kStockNoVncRoot = "/usr/share/novnc";

// A copy of the stock page that sim_rfb can serve: it wants an index.html (the package has vnc.html), and the
// package's links are followed into plain files.
void copy_stock_novnc(const std::filesystem::path& to) {
  namespace fs = std::filesystem;
  fs::copy(kStockNoVncRoot, to, fs::copy_options::recursive);
  fs::copy_file(to / "vnc.html", to / "index.html", fs::copy_options::overwrite_existing);
}

// Where the script opens the client: our page, or noVNC 1.3's vnc.html beside it connecting to the same port
// (sim_rfb upgrades any path), without its reconnect and at its default quality.
std::string page_url(const BrowserClient& client, const CellPath& path) {
  if (client.page == "novnc13") {
    return path.page_url() + "vnc.html?autoconnect=true&reconnect=false&resize=scale&path=websockify";
  }
  return path.page_url();
}

void print_trace(const BrowserRow& row, Clock::time_point started) {
  for (const StreamSample& s : row.samples) {
    std::printf("trace %s RTT %d t=%.1f %s q%.0f level %.0f fps %.1f rtt %.0f/%.0f window %.0f held %.0f\n",
                row.client.name.c_str(), row.rtt_ms, std::chrono::duration<double>(s.at - started).count(),
                s.encoding.c_str(), s.quality, s.quality_level, s.fps, s.last_rtt_ms, s.base_rtt_ms, s.window_bytes,
                s.updates_held);
  }
}

BrowserRow run_browser(SimSettings settings, const std::string& source_dir, const BrowserClient& client, int rtt,
                       const BrowserPlan& plan) {
  BrowserRow row;
  row.client = client;
  row.rtt_ms = rtt;
  std::optional<test::TempDir> web_root;  // only for the stock page; outlives the simulator serving it
  if (client.page == "novnc13") {
    if (!std::filesystem::is_regular_file(std::string(kStockNoVncRoot) + "/vnc.html")) {
      row.error = "no stock noVNC at /usr/share/novnc (apt-get install novnc)";
      return row;
    }
    web_root.emplace("rfbsim-bench-novnc13");
    copy_stock_novnc(web_root->path() / "page");
    settings.extra_args = {"--web-root", (web_root->path() / "page").string()};
  }
  const auto started = Clock::now();
  const auto path =
      open_path(client.path, settings, client.codec, test::link_profile(std::chrono::milliseconds(rtt), plan.cap_mbit));
  StreamSampler sampler(*path);
  const std::string script = (std::filesystem::path(source_dir) / "bench" / "bench_network_browser.mjs").string();
  const std::vector<std::string> args = {
      script, "--url", page_url(client, *path), "--web-dir",
      (std::filesystem::path(source_dir) / "web").string(), "--browser", client.browser, "--page", client.page,
      "--warm-up-ms", std::to_string(plan.warm_up.count() * 1000), "--measure-ms",
      std::to_string(plan.measure.count() * 1000), "--presses", std::to_string(plan.presses), "--threshold",
      fixed(plan.threshold, 1), "--rtt-ms", std::to_string(rtt)};
  const auto limit = plan.warm_up + plan.measure * 3 + std::chrono::seconds(90);
  const test::ExitResult exit = test::run_to_exit(settings.node, args, limit);
  row.samples = sampler.finish();
  if (plan.trace) print_trace(row, started);
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

std::vector<BrowserClient> browser_clients() {
  return {{"auto", "chromium", "bundled", "auto"},
          {"jpeg", "chromium", "bundled", "jpeg"},
          {"h264", "chromium", "bundled", "h264"},
          {"firefox", "firefox", "bundled", "auto"},
          {"firefox-h264", "firefox", "bundled", "h264"},
          {"firefox-manager", "firefox", "bundled", "auto", PathKind::kManager},
          {"novnc13", "chromium", "novnc13", "auto"}};
}

BrowserClient parse_browser_client(const std::string& name) {
  for (const BrowserClient& client : browser_clients()) {
    if (client.name == name) return client;
  }
  throw std::invalid_argument("unknown browser client '" + name + "' (auto, jpeg, h264, firefox, firefox-h264, firefox-manager or novnc13)");
}

std::vector<BrowserRow> run_browser_rows(const SimSettings& settings, const std::string& source_dir,
                                         const BrowserPlan& plan) {
  std::vector<BrowserRow> rows;
  for (const BrowserClient& client : plan.clients) {
    for (const int rtt : plan.rtts) {
      std::fprintf(stderr, "bench_network: browser %s (%s, %s page, --codec %s), RTT %d ms ...\n",
                   client.name.c_str(), client.browser.c_str(), client.page.c_str(), client.codec.c_str(), rtt);
      try {
        rows.push_back(run_browser(settings, source_dir, client, rtt, plan));
      } catch (const std::exception& error) {
        BrowserRow failed;
        failed.client = client;
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
  Table table({"client", "RTT ms", "page fps", "fps / fps at 0", "page Mbit/s", "key p50 ms", "key p90 ms",
               "presses (timed out)", "server fps p50", "server RTT p50", "server chose (at the end)"},
              1);
  double base_fps = kNaN;
  std::string base_client;
  for (const BrowserRow& row : rows) {
    std::vector<std::string> cells{row.client.name, std::to_string(row.rtt_ms)};
    if (!row.error.empty()) {
      cells.push_back("failed: " + row.error);
      table.add_row(std::move(cells));
      continue;
    }
    if (row.rtt_ms == 0) {
      base_fps = row.page_fps;
      base_client = row.client.name;
    }
    const double ratio = base_client == row.client.name ? row.page_fps / base_fps : kNaN;
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
                               text(quantile(row.latencies_ms, 0.5), 0), text(quantile(row.latencies_ms, 0.9), 0),
                               std::to_string(row.presses) + " (" + std::to_string(row.timeouts) + ")",
                               text(quantile(server_fps, 0.5), 1), text(quantile(server_rtt, 0.5), 0), chose});
    table.add_row(std::move(cells));
  }
  table.print();
}

}  // namespace rfbsim::bench
