// SPDX-License-Identifier: GPL-2.0-or-later
// bench_manager: what sim_manager costs a participant, against a real sim_manager and real sim_rfb sessions.
//
// Every client here is libvncclient (RfbTestClient) behind a WsRfbBridge, so it reaches a session the way
// the participant page does: a WebSocket to /s/<token>/ws that the manager relays as raw RFB.
//   1. Link to first frame: GET /start with a fresh uid, then, as soon as the 302 arrives, a client on the
//      redirect's WebSocket; time to the first complete framebuffer update, split into stages. Each
//      session is ended through the admin API, and gone, before the next link.
//   2. Relay cost per update: two clients on one session, A through a bridge to the session's own port
//      (sim_rfb speaks WebSocket itself; a forwarder adds the PROXY line sessions expect first, as the relay
//      does), B through a bridge to the manager. Each pumps on its
//      own thread and records when each update completed, a hash of its picture after it and a small
//      thumbnail of it. Updates of A and B that show the same frame are paired, and t_B - t_A is what the
//      manager's hop added. Bit-identical pictures are rare (see picture_thumb), so frames are paired by
//      thumbnail; the hash only counts how many pairs were also bit-identical.
//   3. Capacity: sessions at 20 fps added one at a time, each watched by one client through the relay;
//      after each, every client's updates per second, until the slowest falls below 19.
// Each table has a manager of its own: table 2's with --session-socket tcp (client A needs the session's port),
// table 3's with --fps 20 (the frame rate is a manager-wide session arg).
// Two further modes replace these three: --soak MINUTES (manager_soak.hpp: sessions cycled through the relay
// while the manager's memory and descriptors are sampled) and --abuse (manager_abuse.hpp: a participant's first
// frame and frame rate on an idle manager and under a /start storm with thousands of half-open sockets).
// The manager runs as rfbsim::test::ManagerUnderTest (tests/support, shared with the manager's process tests);
// the clients and their fingerprints are in manager_clients.hpp.
#include <arpa/inet.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "http_client.hpp"
#include "manager_abuse.hpp"
#include "manager_takeovers.hpp"
#include "manager_clients.hpp"
#include "manager_process.hpp"
#include "manager_session.hpp"
#include "manager_soak.hpp"
#include "proxy_line_forwarder.hpp"

namespace {

namespace bench = rfbsim::bench;
namespace net = rfbsim::test::net;
using bench::Arrival;
using bench::Clock;
using bench::WatchedClient;
using rfbsim::test::IndexRow;
using rfbsim::test::ManagerUnderTest;
using bench::end_session;
using bench::is_live_state;
using bench::start_session;
using bench::wait_for_row;
using std::chrono::milliseconds;

constexpr auto kFirstUpdateTimeout = milliseconds(30000);  // link to first update, and session start
constexpr auto kEndTimeout = milliseconds(20000);          // admin end to the index's final state
constexpr auto kRelayWarmUp = milliseconds(1000);          // table 2: first updates differ (full frames)
constexpr auto kMatchWindow = milliseconds(250);           // table 2: B's update of A's frame is this close
// Table 2: thumbnails of one frame differ in at most this many cells (0 in trial runs), consecutive frames of
// the warehouse in 250 and more.
constexpr int kSameFrameCells = 16;
constexpr auto kCapacityWarmUp = milliseconds(2000);
constexpr auto kCapacityWindow = milliseconds(5000);
constexpr double kCapacityFps = 20.0;
constexpr double kCapacityFloor = 19.0;  // 20 fps less a jitter allowance
// Soak sessions: the scenario's default 1280x720 at 15 fps, half the renderer's work at the default 30 (the
// relay's work per frame is the same), so that a long soak leaves the shared machine some room.
const std::vector<std::string> kSoakSessionArgs = {"--fps", "15"};

struct Options {
  int sessions = 20;
  std::string scenario = "warehouse";
  int seconds = 10;
  int max_capacity = 8;
  bool skip_capacity = false;
  std::string manager = rfbsim::test::sim_manager_path();  // $RFBSIM_SIM_MANAGER, or the one built here
  std::string log = (std::filesystem::temp_directory_path() / "rfbsim_bench_manager.log").string();
  bool soak = false;  // --soak MINUTES given: run the soak instead of tables 1-3
  bench::SoakOptions soak_options;
  bool abuse = false;  // --abuse given: run the abuse comparison instead of tables 1-3
  bench::AbuseOptions abuse_options;
  bool takeover_storm = false;  // --takeover-storm: run only the takeover storm (manager_takeovers.hpp)
  bench::TakeoverStormOptions storm_options;
  std::string manager_before;  // a second sim_manager the storm runs against too, side by side
};

Options parse_options(int argc, char** argv) {
  Options o;
  bench::CommandLine cli(
      "bench_manager",
      "Measures sim_manager: link to first frame, the relay's cost per update, sessions at 20 fps (loopback).\n"
      "--soak cycles sessions through the relay for MINUTES and samples the manager's RSS and descriptors every\n"
      "10 s. --abuse compares a participant's first frame and frame rate on an idle manager with the same while\n"
      "--abuse-from holds --half-open half-open sockets and hammers /start. Both can be given (soak first);\n"
      "either replaces the three default measurements.");
  cli.number("--sessions", o.sessions, 1, 1000, "sessions at once");
  cli.text("--scenario", o.scenario, "the sessions' scenario");
  cli.number("--seconds", o.seconds, 2, 3600, "seconds of frames per measurement");
  cli.number("--max-capacity", o.max_capacity, 1, 64, "the most sessions the capacity table tries");
  cli.flag("--skip-capacity", o.skip_capacity, "leave the capacity table out");
  cli.text("--manager", o.manager, "the sim_manager to run");
  cli.text("--log", o.log, "where sim_manager's output goes");
  cli.value("--soak", o.soak_options.minutes,
            [](const std::string& text) { return static_cast<double>(bench::parse_int(text, 1, 24 * 60, "--soak")); },
            "run the soak for MINUTES (1..1440)")
      ->type_name("MINUTES")->default_str(bench::fixed(o.soak_options.minutes, 0));
  cli.number("--sessions-per-minute", o.soak_options.sessions_per_minute, 1, 600, "the soak's sessions per minute");
  cli.number("--soak-max-sessions", o.soak_options.max_sessions, 1, 64, "the soak's sessions at once");
  cli.number("--watch-seconds", o.soak_options.watch_seconds, 1, 600, "seconds of frames per soak session");
  cli.flag("--abuse", o.abuse, "run the abuse comparison");
  cli.number("--abuse-repetitions", o.abuse_options.repetitions, 1, 100, "abuse comparisons");
  cli.number("--abuse-seconds", o.abuse_options.seconds, 1, 600, "seconds per abuse measurement");
  cli.number("--half-open", o.abuse_options.half_open, 0, 60000, "half-open sockets the abuser holds");
  cli.text("--abuse-from", o.abuse_options.from, "the abuser's IPv4 address")
      ->type_name("ADDR")
      ->check(bench::satisfies(
          [](const std::string& text) {
            in_addr parsed{};
            return ::inet_pton(AF_INET, text.c_str(), &parsed) == 1;
          },
          "an IPv4 address"));
  cli.number("--storm-per-second", o.abuse_options.storm_per_second, 0, 1000, "the abuser's /start calls per second");
  cli.flag("--takeover-storm", o.takeover_storm, "run the takeover storm instead of tables 1-3");
  cli.number("--storm-upgrades", o.storm_options.upgrades, 1, 60000, "the takeover storm's upgrades");
  cli.number("--storm-addresses", o.storm_options.addresses, 1, 240, "the takeover storm's source addresses");
  cli.number("--storm-seconds", o.storm_options.seconds, 1, 600, "the takeover storm's duration");
  cli.text("--manager-before", o.manager_before, "another sim_manager for the takeover storm to compare with");
  cli.parse(argc, argv);
  o.soak = cli.given("--soak");
  return o;
}

// ----------------------------------------------------------------------------------------------------------
// The manager under measurement
// ----------------------------------------------------------------------------------------------------------

// Milliseconds since the epoch of an index time such as "2025-01-31T12:00:00.123Z"; NaN if unparseable.
double iso_ms(const std::string& text) {
  std::tm parts{};
  int millis = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%dT%d:%d:%d.%dZ", &parts.tm_year, &parts.tm_mon, &parts.tm_mday,
                  &parts.tm_hour, &parts.tm_min, &parts.tm_sec, &millis) != 7) {
    return std::nan("");
  }
  parts.tm_year -= 1900;
  parts.tm_mon -= 1;
  return static_cast<double>(::timegm(&parts)) * 1000.0 + millis;
}

bench::ManagerRun manager_run(const Options& options) { return {options.manager, options.log, options.scenario}; }

// ----------------------------------------------------------------------------------------------------------
// 1. Link to first frame
// ----------------------------------------------------------------------------------------------------------

// Stages of one link, each in ms from sending GET /start unless said otherwise.
struct FirstFrameResult {
  std::vector<double> redirect_ms;             // the 302 received
  std::vector<double> ready_ms;                // the index's ready_at (wall clock, 1 ms steps)
  std::vector<double> startup_ms;              // ready_at - created_at: sim_rfb's start-up as the manager saw it
  std::vector<double> handshake_ms;            // RFB handshake done at the client
  std::vector<double> ready_to_handshake_ms;   // handshake_ms - ready_ms
  std::vector<double> first_ms;                // first complete update: the link's time to first frame
  std::vector<double> handshake_to_first_ms;   // first_ms - handshake_ms
  std::vector<double> end_ms;                  // admin end sent -> the index's final state
  std::string renderer = "unknown";
};

double wall_ms(std::chrono::system_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(t.time_since_epoch()).count();
}

FirstFrameResult run_first_frame(const Options& options, const ManagerUnderTest& manager) {
  FirstFrameResult r;
  for (int i = 0; i < options.sessions; ++i) {
    const std::string uid = "bench-first-" + std::to_string(::getpid()) + "-" + std::to_string(i);
    const double t0_wall = wall_ms(std::chrono::system_clock::now());
    const auto t0 = Clock::now();
    const std::string token = start_session(manager, uid, options.scenario);
    const auto redirected = Clock::now();
    // The page's script opens the WebSocket right away; the manager holds it until the session is ready.
    auto client = std::make_unique<WatchedClient>(manager.ws_url(token), manager.origin(), false);
    const auto handshake = Clock::now();
    client->start();
    const auto deadline = Clock::now() + kFirstUpdateTimeout;
    while (client->updates() == 0) {
      if (!client->connected() || Clock::now() > deadline) throw std::runtime_error("no first update for " + uid);
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    client->stop();
    const auto first = client->arrivals().front().at;

    const IndexRow row = wait_for_row(manager, token, [](const IndexRow& x) { return !x.ready_at.empty(); },
                                              kFirstUpdateTimeout, "became ready");
    if (i == 0) r.renderer = bench::renderer_in_log((std::filesystem::path(row.data_path) / "session.log").string());
    const double ready = iso_ms(row.ready_at) - t0_wall;
    r.redirect_ms.push_back(bench::ms_between(t0, redirected));
    r.ready_ms.push_back(ready);
    r.startup_ms.push_back(iso_ms(row.ready_at) - iso_ms(row.created_at));
    r.handshake_ms.push_back(bench::ms_between(t0, handshake));
    r.ready_to_handshake_ms.push_back(bench::ms_between(t0, handshake) - ready);
    r.first_ms.push_back(bench::ms_between(t0, first));
    r.handshake_to_first_ms.push_back(bench::ms_between(handshake, first));

    // Free the capacity, and wait until the session is really gone, before the next link.
    const auto end_sent = Clock::now();
    end_session(manager, row.id);
    wait_for_row(manager, token, [](const IndexRow& x) { return !is_live_state(x.state); }, kEndTimeout, "ended");
    r.end_ms.push_back(bench::ms_between(end_sent, Clock::now()));
  }
  return r;
}

// ----------------------------------------------------------------------------------------------------------
// 2. Relay cost per update
// ----------------------------------------------------------------------------------------------------------

struct RelayRound {
  std::string first_connected;
  std::size_t updates_a = 0, updates_b = 0;        // after the warm-up
  std::size_t unmatched_a = 0, unmatched_b = 0;
  std::size_t identical = 0;                        // matched pairs whose pictures were bit-identical
  std::vector<double> delta_ms;                     // t_B - t_A per matched picture
};

// Pairs each of A's updates with B's update of the same frame: the one within kMatchWindow whose thumbnail
// is closest, at most kSameFrameCells cells apart, each of B's used once. Only A's updates after `from`
// count (the first ones are full frames, sent before the pumps started).
RelayRound match_updates(const std::vector<Arrival>& a, const std::vector<Arrival>& b, Clock::time_point from) {
  RelayRound round;
  std::vector<bool> taken(b.size(), false);
  std::size_t b_matched_after = 0;
  std::size_t window_start = 0;  // b is in time order
  for (const Arrival& x : a) {
    if (x.at < from) continue;
    ++round.updates_a;
    while (window_start < b.size() && b[window_start].at < x.at - kMatchWindow) ++window_start;
    std::size_t best = b.size();
    int best_distance = kSameFrameCells + 1;
    for (std::size_t j = window_start; j < b.size() && b[j].at <= x.at + kMatchWindow; ++j) {
      if (taken[j]) continue;
      const int d = bench::thumb_distance(x.thumb, b[j].thumb, best_distance);
      if (d < best_distance) {
        best = j;
        best_distance = d;
      }
    }
    if (best == b.size()) {
      ++round.unmatched_a;
      continue;
    }
    taken[best] = true;
    if (b[best].at >= from) ++b_matched_after;
    if (b[best].hash == x.hash) ++round.identical;
    round.delta_ms.push_back(bench::ms_between(x.at, b[best].at));
  }
  for (const Arrival& y : b) round.updates_b += y.at >= from ? 1U : 0U;
  round.unmatched_b = round.updates_b - b_matched_after;
  return round;
}

std::vector<RelayRound> run_relay(const Options& options, const ManagerUnderTest& manager) {
  const std::string uid = "bench-relay-" + std::to_string(::getpid());
  const std::string token = start_session(manager, uid, options.scenario);
  const IndexRow row = wait_for_row(manager, token, [](const IndexRow& x) { return x.state == "running"; },
                                            kFirstUpdateTimeout, "became ready");
  // Sessions started by the manager take a PROXY line first (--proxy-protocol), as its relay sends: A goes
  // through a forwarder that sends one, which sim_rfb then trusts instead of checking the Origin.
  const bench::ProxyLineForwarder forwarder(row.port);
  const std::string direct_url = "ws://127.0.0.1:" + std::to_string(forwarder.port()) + "/";
  const std::string direct_origin = "http://127.0.0.1:" + std::to_string(forwarder.port());

  // sim_rfb serves its clients newest first, one after the other, encoding each client's update in
  // turn: whichever connected last gets each frame a little earlier. Both orders, so that this cancels.
  std::vector<RelayRound> rounds;
  for (const bool direct_first : {true, false}) {
    std::unique_ptr<WatchedClient> a, b;
    if (direct_first) {
      a = std::make_unique<WatchedClient>(direct_url, direct_origin, true);
      b = std::make_unique<WatchedClient>(manager.ws_url(token), manager.origin(), true);
    } else {
      b = std::make_unique<WatchedClient>(manager.ws_url(token), manager.origin(), true);
      a = std::make_unique<WatchedClient>(direct_url, direct_origin, true);
    }
    const auto started = Clock::now();
    a->start();
    b->start();
    std::this_thread::sleep_for(kRelayWarmUp + std::chrono::seconds(options.seconds));
    a->stop();
    b->stop();
    if (!a->connected() || !b->connected()) throw std::runtime_error("a relay-test client lost its connection");
    RelayRound round = match_updates(a->arrivals(), b->arrivals(), started + kRelayWarmUp);
    round.first_connected = direct_first ? "A (direct)" : "B (relay)";
    rounds.push_back(std::move(round));
  }
  end_session(manager, row.id);
  wait_for_row(manager, token, [](const IndexRow& x) { return !is_live_state(x.state); }, kEndTimeout, "ended");
  return rounds;
}

// ----------------------------------------------------------------------------------------------------------
// 3. Capacity at 20 fps
// ----------------------------------------------------------------------------------------------------------

struct CapacityRow {
  int sessions = 0;
  double join_ms = 0;  // the newest session: GET /start sent -> RFB handshake done
  std::vector<double> fps;  // per client over the window
  std::string load;
};

std::vector<CapacityRow> run_capacity(const Options& options, const ManagerUnderTest& manager) {
  std::vector<std::unique_ptr<WatchedClient>> clients;
  std::vector<CapacityRow> rows;
  for (int n = 1; n <= options.max_capacity; ++n) {
    const auto t0 = Clock::now();
    const std::string token = start_session(
        manager, "bench-capacity-" + std::to_string(::getpid()) + "-" + std::to_string(n), options.scenario);
    clients.push_back(std::make_unique<WatchedClient>(manager.ws_url(token), manager.origin(), false));
    CapacityRow row;
    row.sessions = n;
    row.join_ms = bench::ms_between(t0, Clock::now());
    clients.back()->start();

    // Every client's updates over the same window, after the newest one has warmed up.
    std::this_thread::sleep_for(kCapacityWarmUp);
    std::vector<std::uint64_t> before;
    for (const auto& c : clients) before.push_back(c->updates());
    const auto from = Clock::now();
    std::this_thread::sleep_for(kCapacityWindow);
    const double seconds = bench::ms_between(from, Clock::now()) / 1000.0;
    for (std::size_t i = 0; i < clients.size(); ++i) {
      row.fps.push_back(static_cast<double>(clients[i]->updates() - before[i]) / seconds);
    }
    row.load = bench::load_average();
    const double slowest = *std::min_element(row.fps.begin(), row.fps.end());
    rows.push_back(std::move(row));
    if (slowest < kCapacityFloor) break;
  }
  for (auto& c : clients) c->stop();
  return rows;
}

// ----------------------------------------------------------------------------------------------------------

void print_summary_row(bench::Table& table, const std::string& stage, const std::vector<double>& samples) {
  const bench::Summary s = bench::summarize(samples);
  table.add_row({stage, std::to_string(s.n), bench::fixed(s.p50, 1), bench::fixed(s.p90, 1),
                 bench::fixed(s.mean, 1), bench::fixed(s.max, 1)});
}

// --soak and --abuse, each against a manager of its own; the soak's limits let one address run it all.
int run_soak_and_abuse(const Options& options, const std::string& load_at_start) {
  const auto started = Clock::now();
  std::printf("bench_manager: CPU %s; load average %s at start; scenario %s; clients: libvncclient (Tight, JPEG) "
              "behind a WsRfbBridge, all on this machine over loopback\n\n",
              bench::cpu_description().c_str(), load_at_start.c_str(), options.scenario.c_str());
  if (options.soak) {
    const bench::SoakOptions& soak = options.soak_options;
    const rfbsim::test::TempDir data("rfbsim-bench-manager");  // outlives the manager
    // Every soak session comes from 127.0.0.1 and many are unseen at once: the per-address limits are off.
    const ManagerUnderTest manager = bench::start_manager(
        manager_run(options), data.path(), kSoakSessionArgs, soak.max_sessions,
        rfbsim::test::without_abuse_limits({"--idle-timeout-s", std::to_string(bench::kSoakIdleTimeoutS)}));
    std::printf("sim_manager (pid %d) with --max-sessions %d --idle-timeout-s %d --rate-start-per-minute 0 "
                "--rate-upgrade-per-minute 0 --max-unspent-sessions-per-address 0; sessions --fps 15\n",
                static_cast<int>(manager.pid()), soak.max_sessions, bench::kSoakIdleTimeoutS);
    bench::print_soak(bench::run_soak(manager, options.scenario, soak), soak);
  }
  if (options.abuse) {
    // The abuser's sockets and the participant's share this process's descriptors; the manager inherits
    // the limit (a deployment raises it the same way, e.g. systemd's LimitNOFILE).
    const long limit = bench::raise_descriptor_limit(options.abuse_options.half_open + 4096L);
    const rfbsim::test::TempDir data("rfbsim-bench-manager");  // outlives the manager
    const ManagerUnderTest manager = bench::start_manager(manager_run(options), data.path(), {}, 4);
    bench::print_abuse(bench::run_abuse(manager, options.scenario, options.abuse_options, limit),
                       options.abuse_options);
  }
  std::printf("sim_manager's stderr: %s; load average %s at the end; total run time %.1f s\n", options.log.c_str(),
              bench::load_average().c_str(), bench::ms_between(started, Clock::now()) / 1000.0);
  return 0;
}

// --takeover-storm: the storm against this build's manager, and against --manager-before where given.
int run_takeover_storm(const Options& options, const std::string& load_at_start) {
  std::printf("bench_manager: CPU %s; load average %s at start\n\n", bench::cpu_description().c_str(),
              load_at_start.c_str());
  bench::raise_descriptor_limit(options.storm_options.upgrades + 4096L);  // every upgrade is held to the end
  std::vector<bench::TakeoverStormResult> results;
  std::vector<std::pair<std::string, std::string>> managers = {{"this build", options.manager}};
  if (!options.manager_before.empty()) managers.insert(managers.begin(), {"before", options.manager_before});
  for (const auto& [label, program] : managers) {
    const std::string log = options.log + "." + (label == "before" ? "before" : "after");
    std::ofstream(log, std::ios::trunc).close();
    results.push_back(bench::run_takeover_storm({program, log, options.scenario}, label + " (" + program + ")",
                                                options.storm_options));
  }
  bench::print_takeover_storm(results, options.storm_options);
  std::printf("load average %s at the end\n", bench::load_average().c_str());
  return 0;
}

int run(const Options& options) {
  if (!std::filesystem::is_regular_file(options.manager)) {
    throw std::runtime_error("no sim_manager at " + options.manager + " (build it, or pass --manager PATH)");
  }
  std::ofstream(options.log, std::ios::trunc).close();
  const std::string load_at_start = bench::load_average();
  if (options.soak || options.abuse) return run_soak_and_abuse(options, load_at_start);
  if (options.takeover_storm) return run_takeover_storm(options, load_at_start);
  const auto started = Clock::now();

  FirstFrameResult first;
  std::vector<RelayRound> relay;
  std::string relay_error;  // table 2 could not run
  {
    const rfbsim::test::TempDir data("rfbsim-bench-manager");  // outlives the manager
    const ManagerUnderTest manager = bench::start_manager(manager_run(options), data.path(), {}, 2);
    first = run_first_frame(options, manager);
  }
  {
    // Client A needs the session's own TCP port; by default the relay reaches sessions by a unix socket.
    const rfbsim::test::TempDir data("rfbsim-bench-manager");  // outlives the manager
    const ManagerUnderTest manager =
        bench::start_manager(manager_run(options), data.path(), {}, 2, {"--session-socket", "tcp"});
    try {
      relay = run_relay(options, manager);
    } catch (const std::runtime_error& error) {
      relay_error = error.what();  // say so, and go on with table 3
    }
  }
  std::vector<CapacityRow> capacity;
  if (!options.skip_capacity) {
    const rfbsim::test::TempDir data("rfbsim-bench-manager");  // outlives the manager
    const ManagerUnderTest manager = bench::start_manager(
        manager_run(options), data.path(), {"--fps", std::to_string(static_cast<int>(kCapacityFps))},
        options.max_capacity);
    capacity = run_capacity(options, manager);
  }

  std::printf("bench_manager: sessions render with %s; CPU %s; load average %s at start\n", first.renderer.c_str(),
              bench::cpu_description().c_str(), load_at_start.c_str());
  std::printf("scenario %s at sim_rfb's default 1280x720; clients: libvncclient (Tight, JPEG) behind a "
              "WsRfbBridge, all on this machine over loopback\n\n",
              options.scenario.c_str());

  std::printf("### 1. Link to first frame (%d sessions in a row; ms from sending GET /start)\n\n", options.sessions);
  bench::Table stages({"stage", "n", "p50", "p90", "mean", "max"}, 1);
  print_summary_row(stages, "/start answered (302 received)", first.redirect_ms);
  print_summary_row(stages, "session ready (index ready_at)", first.ready_ms);
  print_summary_row(stages, "  sim_rfb start-up (ready_at - created_at)", first.startup_ms);
  print_summary_row(stages, "RFB handshake done at the client", first.handshake_ms);
  print_summary_row(stages, "  session ready -> handshake done", first.ready_to_handshake_ms);
  print_summary_row(stages, "first complete update = link to first frame", first.first_ms);
  print_summary_row(stages, "  handshake done -> first update", first.handshake_to_first_ms);
  print_summary_row(stages, "admin end -> session gone (not in the total)", first.end_ms);
  stages.print();
  std::printf("\nTarget: link to first frame under 500 ms median (SEAN-EP: 18.9 s). Indented rows are parts of the "
              "row above; rows from the index have 1 ms steps.\n\n");

  if (!relay_error.empty()) {
    std::printf("### 2. Relay cost per update: not measured (%s)\n\n", relay_error.c_str());
  } else {
    std::printf("### 2. Relay cost per update (one session, %d s per order after a %lld ms warm-up; ms)\n\n",
                options.seconds, static_cast<long long>(kRelayWarmUp.count()));
    bench::Table relay_table({"connected first", "updates A", "updates B", "matched", "bit-identical", "unmatched A",
                              "unmatched B", "t_B - t_A p50", "p90", "mean"},
                             1);
    std::vector<double> pooled;
    for (const RelayRound& r : relay) {
      const bench::Summary s = bench::summarize(r.delta_ms);
      relay_table.add_row({r.first_connected, std::to_string(r.updates_a), std::to_string(r.updates_b),
                           std::to_string(s.n), std::to_string(r.identical), std::to_string(r.unmatched_a),
                           std::to_string(r.unmatched_b),
                           bench::fixed(s.p50, 2), bench::fixed(s.p90, 2), bench::fixed(s.mean, 2)});
      pooled.insert(pooled.end(), r.delta_ms.begin(), r.delta_ms.end());
    }
    const bench::Summary all = bench::summarize(pooled);
    relay_table.add_row({"both orders pooled", "", "", std::to_string(all.n), "", "", "", bench::fixed(all.p50, 2),
                         bench::fixed(all.p90, 2), bench::fixed(all.mean, 2)});
    relay_table.print();
    double order_neutral = 0.0;
    for (const RelayRound& r : relay) {
      order_neutral += bench::summarize(r.delta_ms).p50 / static_cast<double>(relay.size());
    }
    std::printf("\nA: WsRfbBridge -> a PROXY-line forwarder -> the session's port (sim_rfb's own WebSocket); B: WsRfbBridge -> "
                "the manager's /s/<token>/ws -> relay -> the same port.\nsim_rfb encodes and sends each frame to its "
                "clients one after the other, newest connection first, so the order biases t_B - t_A by about one "
                "update's encoding time in opposite directions; the mean of the two orders' medians, %.2f ms, estimates "
                "the relay's cost per update. Target: under 1 ms.\n\n",
                order_neutral);
  }

  if (!options.skip_capacity) {
    std::printf("### 3. Capacity at %.0f fps (one client per session through the relay; updates/s over %lld s "
                "after a %lld ms warm-up)\n\n",
                kCapacityFps, static_cast<long long>(kCapacityWindow.count() / 1000),
                static_cast<long long>(kCapacityWarmUp.count()));
    bench::Table capacity_table(
        {"sessions", "min fps", "median fps", "max fps", "newest: link -> handshake ms", "1-min load"}, 0);
    int largest = 0;
    for (const CapacityRow& row : capacity) {
      const bench::Summary s = bench::summarize(row.fps);
      const double slowest = *std::min_element(row.fps.begin(), row.fps.end());
      if (slowest >= kCapacityFloor && largest == row.sessions - 1) largest = row.sessions;
      capacity_table.add_row({std::to_string(row.sessions), bench::fixed(slowest, 1), bench::fixed(s.p50, 1),
                              bench::fixed(s.max, 1), bench::fixed(row.join_ms, 0), row.load});
    }
    capacity_table.print();
    std::printf("\nLargest count with every client at >= %.0f fps: %d (cap %d). %.0f rather than %.0f allows for "
                "jitter in a 5 s count; the clients, bridges and manager run on this machine too.\n\n",
                kCapacityFloor, largest, options.max_capacity, kCapacityFloor, kCapacityFps);
  }
  std::printf("sim_manager's stderr: %s; total run time %.1f s\n", options.log.c_str(),
              bench::ms_between(started, Clock::now()) / 1000.0);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse_options(argc, argv));
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "bench_manager: %s (--help shows the usage)\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_manager: error: %s\n", error.what());
    return 1;
  }
}
