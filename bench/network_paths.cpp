// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's paths: sim_rfb behind a LinkEmulator, or a sim_manager session behind one (and a WsRfbBridge).
#include "network_paths.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"
#include "ws_rfb_bridge.hpp"

namespace rfbsim::bench {

namespace {

using std::chrono::milliseconds;

constexpr auto kSessionTimeout = milliseconds(30000);  // /start to the session running
const std::string kAdminToken = "bench-network-admin-0123";  // 24 characters; loopback only

// The text of a string field `"key":"value"` in a flat JSON object; "" when absent.
std::string json_string(const std::string& json, const std::string& key) {
  const std::string needle = "\"" + key + "\":\"";
  const auto at = json.find(needle);
  if (at == std::string::npos) return "";
  const auto end = json.find('"', at + needle.size());
  return end == std::string::npos ? "" : json.substr(at + needle.size(), end - at - needle.size());
}

// The number of a field `"key":value` in a flat JSON object; NaN when absent or null.
double json_field(const std::string& json, const std::string& key) {
  const std::string needle = "\"" + key + "\":";
  const auto at = json.find(needle);
  if (at == std::string::npos) return kNaN;
  const char* text = json.c_str() + at + needle.size();
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  return end == text ? kNaN : value;
}

// sim_rfb on a free port, the emulator in front of it; /status.json read on the server's own port.
class DirectPath final : public CellPath {
 public:
  DirectPath(const SimSettings& settings, const std::string& codec, const test::LinkProfile& profile)
      : sim_(start(settings, codec)), link_("127.0.0.1", sim_->port(), profile) {}
  [[nodiscard]] int client_port() const override { return link_.port(); }
  [[nodiscard]] test::LinkEmulator& link() override { return link_; }
  [[nodiscard]] std::string page_url() const override { return "http://127.0.0.1:" + std::to_string(link_.port()) + "/"; }
  [[nodiscard]] std::optional<StreamSample> sample() const override {
    const std::string body = test::http_body(test::http_get(sim_->port(), "/status.json", milliseconds(2000)));
    return parse_status_stream(body);
  }

 private:
  static std::unique_ptr<test::SimProcess> start(const SimSettings& settings, const std::string& codec) {
    std::vector<std::string> args = {"--port", "0"};
    const std::vector<std::string> more = sim_args(settings, codec);
    args.insert(args.end(), more.begin(), more.end());
    args.insert(args.end(), settings.extra_args.begin(), settings.extra_args.end());
    const StderrToFile redirect(settings.log);
    return std::make_unique<test::SimProcess>(settings.sim, args);
  }
  std::unique_ptr<test::SimProcess> sim_;
  mutable test::LinkEmulator link_;
};

// A sim_manager of its own with one session; the emulator in front of the manager, the bridge in front of
// the emulator (the browser's side). The stream report comes from the manager's /metrics.
class ManagerPath final : public CellPath {
 public:
  ManagerPath(const SimSettings& settings, const std::string& codec, const test::LinkProfile& profile)
      : data_("rfbsim-bench-network"), manager_(start(settings, codec, data_.path())) {
    static std::atomic<int> counter{0};
    const std::string uid = "bench-network-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    // The seed goes in the link: the manager sets every session's --seed itself.
    const test::net::HttpResponse response = manager_->start("uid=" + uid + "&scenario=" + settings.scenario +
                                                             "&seed=" + std::to_string(settings.seed));
    token_ = test::token_from_redirect(response);
    if (token_.empty()) {
      throw std::runtime_error("/start answered " + std::to_string(response.status) + ": " +
                               response.body.substr(0, 200));
    }
    const auto row = manager_->wait_for_row(token_, [](const test::IndexRow& r) { return r.state == "running"; },
                                            kSessionTimeout);
    if (!row) throw std::runtime_error("the manager's session never ran (see " + settings.log + ")");
    session_id_ = row->id;
    link_ = std::make_unique<test::LinkEmulator>("127.0.0.1", manager_->port(), profile);
    // The manager accepts a WebSocket whose Origin names the host the browser asked for: the emulator's port.
    const std::string front = "127.0.0.1:" + std::to_string(link_->port());
    bridge_ = std::make_unique<test::WsRfbBridge>("ws://" + front + "/s/" + token_ + "/ws", "http://" + front);
  }
  ~ManagerPath() override {
    bridge_.reset();
    link_.reset();
  }
  ManagerPath(const ManagerPath&) = delete;
  ManagerPath& operator=(const ManagerPath&) = delete;

  [[nodiscard]] int client_port() const override { return bridge_->port(); }
  [[nodiscard]] test::LinkEmulator& link() override { return *link_; }
  [[nodiscard]] std::string page_url() const override {
    return "http://127.0.0.1:" + std::to_string(link_->port()) + "/s/" + token_ + "/";
  }
  [[nodiscard]] std::optional<StreamSample> sample() const override {
    const test::net::HttpResponse response = manager_->get("/metrics");
    if (response.status != 200) return std::nullopt;
    const std::string label = "{session=\"" + std::to_string(session_id_) + "\"";
    StreamSample s;
    s.at = Clock::now();
    std::istringstream lines(response.body);
    std::string line;
    bool any = false;
    while (std::getline(lines, line)) {
      const auto value = [&] { return std::strtod(line.c_str() + line.rfind(' ') + 1, nullptr); };
      if (line.rfind("rfbsim_session_rtt_ms" + label + "}", 0) == 0) {
        s.last_rtt_ms = value();
        any = true;
      } else if (line.rfind("rfbsim_session_fps" + label + "}", 0) == 0) {
        s.fps = value();
        any = true;
      } else if (line.rfind("rfbsim_session_quality" + label + "}", 0) == 0) {
        s.quality = value();
        any = true;
      } else if (line.rfind("rfbsim_session_codec_info" + label + ",codec=\"", 0) == 0) {
        const auto from = line.find("codec=\"") + 7;
        s.encoding = line.substr(from, line.find('"', from) - from);
        any = true;
      }
    }
    if (!any) return std::nullopt;
    return s;
  }

 private:
  static std::unique_ptr<test::ManagerUnderTest> start(const SimSettings& settings, const std::string& codec,
                                                       const std::filesystem::path& data_dir) {
    std::vector<std::string> flags = {"--max-sessions", "1", "--admin-token", kAdminToken, "--scenarios",
                                      settings.scenario, "--max-duration-s", "3600", "--codec", codec};
    // The manager passes the scenario and the codec itself, and the seed from the link.
    std::vector<std::string> session = sim_args(settings, codec);
    for (std::size_t i = 0; i < session.size(); ++i) {
      if (session[i] == "--scenario" || session[i] == "--codec" || session[i] == "--seed") {
        ++i;
        continue;
      }
      flags.insert(flags.end(), {"--session-arg", session[i]});
    }
    test::ManagerOptions how;
    how.program = settings.manager;
    how.stop_signal = SIGTERM;
    how.stop_timeout = milliseconds(30000);
    how.poll_interval = milliseconds(20);
    const StderrToFile redirect(settings.log);
    return std::make_unique<test::ManagerUnderTest>(data_dir, flags, how);
  }

  test::TempDir data_;  // outlives the manager
  std::unique_ptr<test::ManagerUnderTest> manager_;
  std::string token_;
  std::int64_t session_id_ = 0;
  std::unique_ptr<test::LinkEmulator> link_;
  std::unique_ptr<test::WsRfbBridge> bridge_;
};

}  // namespace

StreamSampler::StreamSampler(const CellPath& path) : thread_([this, &path] { loop(path); }) {}

StreamSampler::~StreamSampler() { finish(); }

void StreamSampler::loop(const CellPath& path) {
  constexpr auto kEvery = milliseconds(500);
  while (!stop_.load()) {
    if (auto sample = path.sample()) {
      const std::lock_guard lock(mutex_);
      samples_.push_back(std::move(*sample));
    }
    const auto next = Clock::now() + kEvery;
    while (!stop_.load() && Clock::now() < next) std::this_thread::sleep_for(milliseconds(20));
  }
}

std::vector<StreamSample> StreamSampler::finish(Clock::time_point from) {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
  std::vector<StreamSample> kept;
  for (const StreamSample& s : samples_) {
    if (s.at >= from) kept.push_back(s);
  }
  return kept;
}

const char* path_name(PathKind kind) { return kind == PathKind::kDirect ? "direct" : "manager"; }

PathKind parse_path(const std::string& name) {
  if (name == "direct") return PathKind::kDirect;
  if (name == "manager") return PathKind::kManager;
  throw std::invalid_argument("unknown path '" + name + "' (direct or manager)");
}

std::vector<std::string> sim_args(const SimSettings& settings, const std::string& codec) {
  std::vector<std::string> args = {"--scenario", settings.scenario, "--fps", std::to_string(settings.fps),
                                   "--seed", std::to_string(settings.seed), "--codec", codec};
  if (!settings.avatar_start.empty()) args.insert(args.end(), {"--avatar-start", settings.avatar_start});
  return args;
}

std::optional<StreamSample> parse_status_stream(const std::string& json) {
  const auto streams = json.find("\"streams\":[");
  if (streams == std::string::npos) return std::nullopt;
  const auto open = json.find('{', streams);
  const auto close = json.find('}', streams);
  if (open == std::string::npos || close == std::string::npos || close < open) return std::nullopt;
  const std::string entry = json.substr(open, close - open + 1);
  StreamSample s;
  s.at = Clock::now();
  s.encoding = json_string(entry, "encoding");
  s.base_rtt_ms = json_field(entry, "base_rtt_ms");  // null reads as NaN
  s.last_rtt_ms = json_field(entry, "last_rtt_ms");
  s.window_bytes = json_field(entry, "window_bytes");
  s.updates_held = json_field(entry, "updates_held");
  s.quality = json_field(entry, "quality");
  s.quality_level = json_field(entry, "quality_level");
  s.fps = json_field(entry, "fps");
  return s;
}

std::unique_ptr<CellPath> open_path(PathKind kind, const SimSettings& settings, const std::string& codec,
                                    const test::LinkProfile& profile) {
  if (kind == PathKind::kDirect) return std::make_unique<DirectPath>(settings, codec, profile);
  return std::make_unique<ManagerPath>(settings, codec, profile);
}

}  // namespace rfbsim::bench
