// SPDX-License-Identifier: GPL-2.0-or-later
// bench_latency: from a key press to the first update that shows it, against a real sim_rfb process.
//
// Per configuration (frame size, frame rate) one sim_rfb runs on loopback and one libvncclient client
// watches it. Each sample:
//   1. let the picture settle: no update for --settle-ms (a still avatar renders identical frames, and
//      the server sends nothing for a frame that changed no tile);
//   2. wait a random 0..100 ms, so that the press lands at every phase of the sim's tick and frame clocks;
//   3. record the client's picture, press the key (default 'd': turning changes most of the picture) at t0;
//   4. pump updates until the picture differs from the recorded one by a mean absolute difference above
//      --threshold (0..255 per channel): that update's arrival - t0 is the sample; the arrival of the
//      first update of all is kept too (the earliest frame that moved at all);
//   5. release the key and go back to 1.
// libvncserver without ContinuousUpdates sends at most one update per request; libvncclient requests the
// next one as soon as it has handled an update, so an update is at most one round trip behind a frame.
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"

#ifndef RFBSIM_BENCH_SIM_RFB
#define RFBSIM_BENCH_SIM_RFB "sim_rfb"
#endif

namespace {

namespace bench = rfbsim::bench;
using bench::Clock;
using std::chrono::milliseconds;

constexpr auto kSampleTimeout = milliseconds(5000);   // a press that shows nothing this long is a timeout
constexpr auto kSettleLimit = milliseconds(15000);    // a picture that never settles ends the run
constexpr int kJitterRangeMs = 100;                   // a multiple of both the 1/30 s and 1/60 s periods

struct Options {
  int samples = 30;
  std::vector<bench::Size> sizes{{1280, 720}, {640, 480}};
  std::vector<int> fps{30, 60};
  double threshold = 2.0;
  int settle_ms = 300;
  std::uint32_t key = 'd';
  std::string sim = RFBSIM_BENCH_SIM_RFB;
  std::string sim_log = (std::filesystem::temp_directory_path() / "rfbsim_bench_latency_sim.log").string();
};

Options parse_options(int argc, char** argv) {
  Options o;
  bench::CommandLine cli("bench_latency",
                         "Measures key press to visible update against a real sim_rfb over loopback (libvncclient).");
  cli.number("--samples", o.samples, 1, 100000, "key presses per size and frame rate");
  cli.list("--sizes", o.sizes, [](const std::string& item) { return bench::parse_sizes(item).at(0); },
           "frame sizes, WxH each");
  cli.list("--fps", o.fps, bench::int_in(1, 240, "--fps"), "frame rates");
  cli.app().add_option("--threshold", o.threshold, "MAD above which a frame shows the key's effect")
      ->type_name("MAD")->capture_default_str();
  cli.number("--settle-ms", o.settle_ms, 10, 10000, "ms to wait between presses");
  cli.value("--key", o.key, bench::parse_key, "the key pressed (one character)")
      ->type_name("CHAR")->default_str(std::string(1, static_cast<char>(o.key)));
  cli.text("--sim", o.sim, "the sim_rfb to run");
  cli.text("--sim-log", o.sim_log, "where sim_rfb's output goes");
  cli.parse(argc, argv);
  return o;
}

// Pumps until no update has arrived for `quiet`. Throws if that never happens or the connection drops.
void settle(rfbsim::test::RfbTestClient& client, milliseconds quiet) {
  const auto deadline = Clock::now() + kSettleLimit;
  for (;;) {
    const std::uint64_t seen = client.updates();
    const bool got = client.pump_until([&] { return client.updates() != seen; }, quiet);
    if (!client.connected()) throw std::runtime_error("the connection to sim_rfb dropped");
    if (!got) return;
    if (Clock::now() > deadline) throw std::runtime_error("the picture never settled");
  }
}

struct ConfigResult {
  std::vector<double> first_ms;    // press -> first update of all
  std::vector<double> visible_ms;  // press -> first update past the threshold
  std::vector<double> updates;     // updates received up to and including the visible one
  int timeouts = 0;
};

ConfigResult run_config(const Options& options, const bench::Size& size, int fps, std::mt19937& rng) {
  std::unique_ptr<rfbsim::test::SimProcess> sim;
  {
    const bench::StderrToFile redirect(options.sim_log);
    sim = std::make_unique<rfbsim::test::SimProcess>(
        options.sim, std::vector<std::string>{"--port", "0", "--width", std::to_string(size.width), "--height",
                                              std::to_string(size.height), "--fps", std::to_string(fps)});
  }
  rfbsim::test::RfbTestClient client("127.0.0.1", sim->port());
  if (!client.wait_for_updates(1, milliseconds(10000))) throw std::runtime_error("no first update from sim_rfb");
  settle(client, milliseconds(options.settle_ms));

  ConfigResult result;
  std::uniform_int_distribution<int> jitter_ms(0, kJitterRangeMs - 1);
  std::vector<std::uint8_t> reference;
  for (int i = 0; i < options.samples; ++i) {
    std::this_thread::sleep_for(milliseconds(jitter_ms(rng)));
    const rfbsim::FrameView shown = client.frame();
    reference.assign(shown.pixels, shown.pixels + shown.row_bytes() * static_cast<std::size_t>(shown.height));
    const rfbsim::FrameView recorded{reference.data(), shown.width, shown.height, shown.stride};

    // Press at t0, then judge each update as it completes; the arrival time is taken before comparing.
    const std::uint64_t updates_before = client.updates();
    std::uint64_t seen = updates_before;
    Clock::time_point first{};
    Clock::time_point visible{};
    const auto t0 = Clock::now();
    client.send_key(options.key, true);
    const bool shown_in_time = client.pump_until(
        [&] {
          if (client.updates() == seen) return false;
          seen = client.updates();
          const auto arrived = Clock::now();
          if (first == Clock::time_point{}) first = arrived;
          if (rfbsim::test::mean_abs_difference(client.frame(), recorded) <= options.threshold) return false;
          visible = arrived;
          return true;
        },
        kSampleTimeout);
    client.send_key(options.key, false);
    if (!client.connected()) throw std::runtime_error("the connection to sim_rfb dropped");
    if (shown_in_time) {
      result.first_ms.push_back(bench::ms_between(t0, first));
      result.visible_ms.push_back(bench::ms_between(t0, visible));
      result.updates.push_back(static_cast<double>(seen - updates_before));
    } else {
      ++result.timeouts;
    }
    settle(client, milliseconds(options.settle_ms));
  }
  sim->stop(SIGTERM);
  return result;
}

int run(const Options& options) {
  if (!std::filesystem::is_regular_file(options.sim)) {
    throw std::runtime_error("no sim_rfb at " + options.sim + " (build it, or pass --sim PATH)");
  }
  std::ofstream(options.sim_log, std::ios::trunc).close();
  bench::Table table({"size", "fps", "n", "first update p50 / p90", "visible p50", "p90", "p99", "mean", "max",
                      "updates p50", "timeouts"});
  const std::string load_at_start = bench::load_average();
  std::mt19937 rng(1);
  const auto started = Clock::now();
  for (const bench::Size& size : options.sizes) {
    for (int fps : options.fps) {
      const ConfigResult r = run_config(options, size, fps, rng);
      const bench::Summary visible = bench::summarize(r.visible_ms);
      table.add_row({size.text(), std::to_string(fps), std::to_string(visible.n),
                     bench::p50_p90(bench::summarize(r.first_ms), 1), bench::fixed(visible.p50, 1),
                     bench::fixed(visible.p90, 1), bench::fixed(visible.p99, 1), bench::fixed(visible.mean, 1),
                     bench::fixed(visible.max, 1), bench::fixed(bench::summarize(r.updates).p50, 0),
                     std::to_string(r.timeouts)});
    }
  }

  std::printf("bench_latency: sim_rfb rendering with %s; CPU %s; load average %s at start\n",
              bench::renderer_in_log(options.sim_log).c_str(), bench::cpu_description().c_str(), load_at_start.c_str());
  std::printf("key '%c' down -> first update with mean abs difference > %.1f from the settled picture; ms over "
              "loopback, libvncclient, JPEG q80 4:2:0, sim ticks at 60 Hz\n\n",
              static_cast<char>(options.key), options.threshold);
  table.print();
  std::printf("\nfirst update = the earliest update after the press (any change); visible = past the threshold.\n");
  std::printf("sim_rfb's stderr: %s; total run time %.1f s\n", options.sim_log.c_str(),
              bench::ms_between(started, Clock::now()) / 1000.0);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse_options(argc, argv));
  } catch (const std::invalid_argument& error) {
    std::fprintf(stderr, "bench_latency: %s (--help shows the usage)\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_latency: error: %s\n", error.what());
    return 1;
  }
}
