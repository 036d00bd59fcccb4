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
//   3. noVNC in Chromium (bench_network_browser.mjs) through the emulator at each RTT, no cap: pictures per
//      second in the page and the encoding the server chose (network_browser.hpp).
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
  int codec_frames = 150;                          // 0 = no codec tables (lockstep and live)
  bool mad_trace = false;
  std::uint32_t turn_key = 'd';
  bench::SimSettings sim;
  std::string source_dir = RFBSIM_BENCH_SOURCE_DIR;
};

constexpr const char* kUsage =
    "usage: bench_network [--rtts MS,...] [--caps none|MBIT,...] [--clients fbur,cu,h264] [--paths direct,manager]\n"
    "                     [--seconds S] [--warm-up S] [--presses N] [--threshold MAD] [--seed N]\n"
    "                     [--long-seconds S] [--browser-rtts none|MS,...] [--codec-frames N] [--mad-trace]\n"
    "                     [--key CHAR]\n"
    "                     [--sim PATH] [--manager PATH] [--node PATH] [--source-dir DIR] [--log PATH]\n"
    "Frames, bytes and key-to-picture latency of the warehouse walking at 1280x720 through an emulated link.\n"
    "--long-seconds 0, --browser-rtts none and --codec-frames 0 skip parts 2, 3 and 4. --mad-trace prints each\n"
    "press's MAD series (to choose --threshold; --key x, a key the avatar ignores, gives the walk alone).\n";

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
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    }
    if (arg == "--mad-trace") {
      o.mad_trace = true;
      continue;
    }
    if (i + 1 >= argc) throw std::invalid_argument("option " + arg + " needs a value");
    const std::string value = argv[++i];
    if (arg == "--rtts") {
      o.rtts = parse_rtts(value);
    } else if (arg == "--caps") {
      o.caps.clear();
      for (const std::string& item : bench::split_list(value)) {
        o.caps.push_back(item == "none" ? 0.0 : bench::parse_int(item, 1, 10000, "cap"));
      }
    } else if (arg == "--clients") {
      o.clients.clear();
      for (const std::string& item : bench::split_list(value)) o.clients.push_back(bench::parse_client(item));
    } else if (arg == "--paths") {
      o.paths.clear();
      for (const std::string& item : bench::split_list(value)) o.paths.push_back(bench::parse_path(item));
    } else if (arg == "--seconds") {
      o.seconds = bench::parse_int(value, 1, 3600, arg);
    } else if (arg == "--warm-up") {
      o.warm_up = bench::parse_int(value, 0, 600, arg);
    } else if (arg == "--presses") {
      o.presses = bench::parse_int(value, 0, 10000, arg);
    } else if (arg == "--threshold") {
      o.threshold = bench::parse_int(value, 1, 255, arg);
    } else if (arg == "--seed") {
      o.sim.seed = static_cast<std::uint64_t>(bench::parse_int(value, 0, 1000000000, arg));
    } else if (arg == "--long-seconds") {
      o.long_seconds = bench::parse_int(value, 0, 3600, arg);
    } else if (arg == "--browser-rtts") {
      o.browser_rtts = parse_rtts(value);
    } else if (arg == "--codec-frames") {
      o.codec_frames = bench::parse_int(value, 0, 100000, arg);
    } else if (arg == "--sim") {
      o.sim.sim = value;
    } else if (arg == "--manager") {
      o.sim.manager = value;
    } else if (arg == "--source-dir") {
      o.source_dir = value;
    } else if (arg == "--key") {
      if (value.size() != 1) throw std::invalid_argument("--key takes one character");
      o.turn_key = static_cast<unsigned char>(value[0]);
    } else if (arg == "--node") {
      o.sim.node = value;
    } else if (arg == "--log") {
      o.sim.log = value;
    } else {
      throw std::invalid_argument("unknown option " + arg);
    }
  }
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
    browser_rows = bench::run_browser_rows(options.sim, options.source_dir, options.browser_rtts,
                                           std::chrono::seconds(options.warm_up), std::chrono::seconds(options.seconds),
                                           options.presses, options.threshold);
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
    std::fprintf(stderr, "bench_network: %s\n%s", error.what(), kUsage);
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_network: error: %s\n", error.what());
    return 1;
  }
}
