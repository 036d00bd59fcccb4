// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network: frames, bytes and key-to-picture latency on a participant's kind of network, against real
// sim_rfb processes (and sim_manager sessions), through a LinkEmulator (one-way delay each way, a rate cap
// with a bounded bottleneck queue and backpressure; no socket signal reaches the server).
//
//   1. The matrix: RTT x downstream cap x client (fbur, cu, h264; network_clients.hpp) x path (direct,
//      manager; network_paths.hpp). Each cell is a fresh simulator (warehouse, 1280x720, --fps 30, a fixed
//      seed) with one client; the participant walks and turns (network_cells.hpp). One table per path, then
//      fps ratios against RTT 0, key-to-picture against RTT, and H.264's bytes against Tight JPEG's.
//   2. The long run: 60 s at 50 ms RTT and 5 Mbit/s (cu and h264): latency in the first and the last 20 s.
//   3. Browsers (bench_network_browser.mjs) through the emulator at each RTT, no cap: our page in Chromium (the
//      default codec, jpeg, h264) and Firefox, and stock noVNC 1.3: pictures per second in the page, key to
//      picture, and the encoding and quality the server chose (network_browser.hpp).
//   4. H.264 against Tight JPEG q80 on the same rendered frames, in process: SSIM against the frame, bytes and
//      encode time per 720p frame, one frame at a time (network_codec.hpp), and as live streams paced by the
//      congestion control through the emulator, no cap and 50 ms + 5 Mbit/s (network_tagged.hpp).
// Cells run one at a time: the simulator's rendering alone takes most of a core.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "manager_process.hpp"
#include "network_browser.hpp"
#include "network_codec.hpp"
#include "network_report.hpp"
#include "network_tagged.hpp"

#ifndef RFBSIM_BENCH_SIM_RFB
#define RFBSIM_BENCH_SIM_RFB "sim_rfb"
#endif
#ifndef RFBSIM_BENCH_SOURCE_DIR
#define RFBSIM_BENCH_SOURCE_DIR "."
#endif

namespace {

namespace bench = rfbsim::bench;
using bench::Clock;
using std::chrono::milliseconds;

constexpr auto kConnectTimeout = milliseconds(30000);  // handshake and first picture, through any link
constexpr int kLongRttMs = 50;                         // the long run's link
constexpr double kLongCapMbit = 5;
constexpr double kLongPartS = 20;                      // first and last part compared

struct Options {
  std::vector<int> rtts{0, 50, 100, 200};
  std::vector<double> caps{0, 10, 5};
  std::vector<bench::ClientKind> clients{bench::ClientKind::kFbur, bench::ClientKind::kCu, bench::ClientKind::kH264};
  std::vector<bench::PathKind> paths{bench::PathKind::kDirect, bench::PathKind::kManager};
  int seconds = 10;
  int warm_up = 3;
  int presses = 10;
  double threshold = 12.0;
  int long_seconds = 60;  // 0 = no long run
  std::vector<int> browser_rtts{0, 50, 100, 200};  // empty = no browser rows
  std::vector<bench::BrowserClient> browser_clients = bench::browser_clients();
  bool browser_trace = false;
  int browser_cap = 0;  // Mbit/s, 0 = none
  int codec_frames = 150;                          // 0 = no codec tables (lockstep and live)
  bool mad_trace = false;
  std::uint32_t turn_key = 'd';
  bench::SimSettings sim;
  std::string source_dir = RFBSIM_BENCH_SOURCE_DIR;
};

std::vector<int> parse_rtts(const std::string& text) {
  std::vector<int> out;
  if (text == "none") return out;
  for (const std::string& item : bench::split_list(text)) out.push_back(bench::parse_int(item, 0, 5000, "RTT"));
  return out;
}

Options parse_options(int argc, char** argv) {
  Options o;
  o.sim.sim = RFBSIM_BENCH_SIM_RFB;
  o.sim.manager = rfbsim::test::sim_manager_path();
  o.sim.log = (std::filesystem::temp_directory_path() / "rfbsim_bench_network.log").string();
  // In the loading area, heading north: the walk's turns to the right circle it there (radius about 2.4 m).
  o.sim.avatar_start = "10,4.5,1.5708";
  bench::CommandLine cli(
      "bench_network",
      "Frames, bytes and key-to-picture latency of the warehouse walking at 1280x720 through an emulated link.\n"
      "--long-seconds 0, --browser-rtts none and --codec-frames 0 skip parts 2, 3 and 4. --mad-trace prints each\n"
      "press's MAD series (to choose --threshold; --key x, a key the avatar ignores, gives the walk alone).");
  const auto ms = [](int value) { return std::to_string(value); };
  cli.value("--rtts", o.rtts, parse_rtts, "round-trip times in ms (MS,... or none)")
      ->type_name("MS,...")->default_str(bench::joined(o.rtts, ms));
  cli.list("--caps", o.caps,
           [](const std::string& item) {
             return item == "none" ? 0.0 : static_cast<double>(bench::parse_int(item, 1, 10000, "cap"));
           },
           [](double cap) { return cap == 0 ? std::string("none") : bench::fixed(cap, 0); },
           "link capacities in Mbit/s (none: no cap)");
  cli.list("--clients", o.clients, bench::parse_client, bench::client_name, "clients: fbur, cu, h264");
  cli.list("--paths", o.paths, bench::parse_path, bench::path_name, "paths: direct, manager");
  cli.number("--seconds", o.seconds, 1, 3600, "seconds per measurement");
  cli.number("--warm-up", o.warm_up, 0, 600, "seconds before measuring");
  cli.number("--presses", o.presses, 0, 10000, "key presses per measurement");
  cli.value("--threshold", o.threshold,
            [](const std::string& text) { return static_cast<double>(bench::parse_int(text, 1, 255, "--threshold")); },
            "MAD above which a frame shows the key's effect (1..255)")
      ->type_name("MAD")->default_str(bench::fixed(o.threshold, 0));
  cli.number("--seed", o.sim.seed, std::uint64_t{0}, std::uint64_t{1000000000}, "sim_rfb's seed: the same crowd in every cell");
  cli.number("--long-seconds", o.long_seconds, 0, 3600, "seconds of the lag check (0: none)");
  cli.value("--browser-rtts", o.browser_rtts, parse_rtts, "noVNC's round-trip times in ms (MS,... or none)")
      ->type_name("MS,...")->default_str(bench::joined(o.browser_rtts, ms));
  cli.list("--browser-clients", o.browser_clients, bench::parse_browser_client,
           [](const bench::BrowserClient& client) { return client.name; },
           "browser clients: auto (our page, Chromium, the default codec), jpeg, h264, firefox (our page, default "
           "codec), firefox-h264, firefox-manager (a sim_manager session), novnc13 (Debian's stock noVNC 1.3 page, Chromium)");
  cli.number("--browser-cap", o.browser_cap, 0, 10000, "the browser rows' link cap in Mbit/s (0: none)");
  cli.flag("--browser-trace", o.browser_trace, "print sim_rfb's stream reports of each browser run");
  cli.number("--codec-frames", o.codec_frames, 0, 100000, "frames of the codec tables (0: none)");
  cli.flag("--mad-trace", o.mad_trace, "print each press's MAD series");
  cli.value("--key", o.turn_key, bench::parse_key, "the key pressed (one character)")
      ->type_name("CHAR")->default_str(std::string(1, static_cast<char>(o.turn_key)));
  cli.text("--sim", o.sim.sim, "the sim_rfb to run");
  cli.text("--manager", o.sim.manager, "the sim_manager to run");
  cli.text("--node", o.sim.node, "the node that runs the browser part");
  cli.text("--source-dir", o.source_dir, "rfbsim's source tree (for the browser part's scripts)");
  cli.text("--log", o.sim.log, "where the programs' output goes");
  cli.parse(argc, argv);
  return o;
}

// One cell: a fresh path and client, the walk, the measures.
bench::CellResult run_one(const Options& options, bench::PathKind path_kind, int rtt_ms, double cap_mbit,
                          bench::ClientKind client_kind, const bench::CellPlan& plan, std::mt19937& rng) {
  const auto profile = rfbsim::test::link_profile(milliseconds(rtt_ms), cap_mbit);
  const auto path = bench::open_path(path_kind, options.sim, bench::codec_for(client_kind), profile);
  const auto client = bench::connect_client(client_kind, path->client_port(), kConnectTimeout);
  bench::CellPlan with_rtt = plan;
  with_rtt.rtt = milliseconds(rtt_ms);
  return bench::run_cell(*client, *path, with_rtt, rng);
}

bench::CellPlan plan_of(const Options& options, int seconds, int presses) {
  bench::CellPlan plan;
  plan.warm_up = std::chrono::seconds(options.warm_up);
  plan.measure = std::chrono::seconds(seconds);
  plan.presses = presses;
  plan.press_every = milliseconds(presses > 0 ? 1000 * seconds / presses : 1000 * seconds);
  plan.threshold = options.threshold;
  plan.trace = options.mad_trace;
  plan.turn_key = options.turn_key;
  return plan;
}

std::string cell_title(bench::PathKind path, int rtt, double cap, bench::ClientKind client) {
  return std::string(bench::path_name(path)) + " " + bench::client_name(client) + " RTT " + std::to_string(rtt) +
         " ms cap " + bench::cap_text(cap);
}

int run(const Options& options) {
  for (const std::string& program : {options.sim.sim, options.sim.manager}) {
    if (!std::filesystem::is_regular_file(program)) throw std::runtime_error("no program at " + program);
  }
  std::ofstream(options.sim.log, std::ios::trunc).close();
  const std::string load_at_start = bench::load_average();
  const auto started = Clock::now();
  std::mt19937 rng(1);

  // 1. The matrix, one cell at a time, progress on stderr.
  std::vector<bench::MatrixCell> cells;
  const bench::CellPlan plan = plan_of(options, options.seconds, options.presses);
  for (const bench::PathKind path : options.paths) {
    for (const bench::ClientKind client : options.clients) {
      for (const double cap : options.caps) {
        for (const int rtt : options.rtts) {
          bench::MatrixCell cell{path, rtt, cap, client, {}, {}, {}};
          const std::string title = cell_title(path, rtt, cap, client);
          std::fprintf(stderr, "bench_network: %s ...\n", title.c_str());
          try {
            cell.result = run_one(options, path, rtt, cap, client, plan, rng);
          } catch (const std::exception& error) {
            cell.error = error.what();
            std::fprintf(stderr, "bench_network: %s failed: %s\n", title.c_str(), error.what());
          }
          cell.load = bench::load_average();
          if (options.mad_trace && cell.error.empty()) bench::print_traces(title, cell.result);
          cells.push_back(std::move(cell));
        }
      }
    }
  }

  // 2. The long run.
  std::vector<bench::LongRun> long_runs;
  if (options.long_seconds > 0) {
    const bench::CellPlan long_plan = plan_of(options, options.long_seconds, options.long_seconds);
    for (const bench::PathKind path : options.paths) {
      for (const bench::ClientKind client : {bench::ClientKind::kCu, bench::ClientKind::kH264}) {
        bench::LongRun run{path, client, {}, {}};
        std::fprintf(stderr, "bench_network: long run %s ...\n",
                     cell_title(path, kLongRttMs, kLongCapMbit, client).c_str());
        try {
          run.result = run_one(options, path, kLongRttMs, kLongCapMbit, client, long_plan, rng);
        } catch (const std::exception& error) {
          run.error = error.what();
        }
        long_runs.push_back(std::move(run));
      }
    }
  }

  // 3. noVNC in Chromium.
  std::vector<bench::BrowserRow> browser_rows;
  if (!options.browser_rtts.empty()) {
    bench::BrowserPlan browser_plan;
    browser_plan.clients = options.browser_clients;
    browser_plan.rtts = options.browser_rtts;
    browser_plan.cap_mbit = options.browser_cap;
    browser_plan.warm_up = std::chrono::seconds(options.warm_up);
    browser_plan.measure = std::chrono::seconds(options.seconds);
    browser_plan.presses = options.presses;
    browser_plan.threshold = options.threshold;
    browser_plan.trace = options.browser_trace;
    browser_rows = bench::run_browser_rows(options.sim, options.source_dir, browser_plan);
  }

  // 4. H.264 against JPEG on the same frames.
  bench::CodecComparison codec;
  std::vector<bench::TaggedRun> live;
  if (options.codec_frames > 0) {
    codec = bench::compare_codecs(options.sim, options.source_dir, options.codec_frames);
    live = bench::run_tagged(options.sim, options.source_dir, {{0, 0.0}, {kLongRttMs, kLongCapMbit}}, options.warm_up,
                             options.seconds);
  }

  std::printf("bench_network: sim_rfb rendering with %s (software, on the CPU); CPU %s; load average %s at start\n",
              bench::renderer_in_log(options.sim.log).c_str(), bench::cpu_description().c_str(), load_at_start.c_str());
  std::printf("scenario %s at 1280x720, --fps %d, --seed %llu, avatar from %s walking (W held) and turning (D for %lld "
              "ms about every %lld ms); %d s warm-up, then at least %d s and %d presses per cell\n",
              options.sim.scenario.c_str(), options.sim.fps, static_cast<unsigned long long>(options.sim.seed),
              options.sim.avatar_start.c_str(), static_cast<long long>(plan.turn_hold.count()),
              static_cast<long long>(plan.press_every.count()), options.warm_up, options.seconds, options.presses);
  std::printf("link: LinkEmulator, RTT split evenly, the cap on both directions, 256 KiB bottleneck queue; "
              "key-to-picture threshold: MAD > %.0f\n\n",
              options.threshold);
  for (const bench::PathKind path : options.paths) {
    std::printf("### Matrix, %s path\n\n", bench::path_name(path));
    bench::print_matrix(cells, path);
    std::printf("\n");
  }
  std::printf("### fps against RTT (fps at each RTT / fps at 0 ms)\n\n");
  bench::print_ratios(cells);
  std::printf("\n### Key-to-picture and bytes\n\n");
  bench::print_latency_and_bytes(cells);
  if (!long_runs.empty()) {
    std::printf("\n### Long run (growing lag?)\n\n");
    bench::print_long_runs(long_runs, kLongRttMs, kLongCapMbit, kLongPartS);
  }
  if (!browser_rows.empty()) {
    std::printf("\n### noVNC in Chromium\n\n");
    bench::print_browser_rows(browser_rows);
  }
  if (options.codec_frames > 0) {
    std::printf("\n### H.264 against Tight JPEG on the same rendered frames\n\n");
    bench::print_codec_comparison(codec);
    std::printf("\n### H.264 against Tight JPEG as live streams (in process, tagged frames)\n\n");
    bench::print_tagged(live);
  }
  std::printf("\nchildren's stderr: %s; total run time %.1f s\n", options.sim.log.c_str(),
              bench::ms_between(started, Clock::now()) / 1000.0);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse_options(argc, argv));
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "bench_network: %s (--help shows the usage)\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_network: error: %s\n", error.what());
    return 1;
  }
}
