// SPDX-License-Identifier: GPL-2.0-or-later
// bench_session_kinds: what one participant's session costs for each of sim_manager's session kinds, at the same
// picture size: sim_rfb (our simulator, the lab scenario), rfb (examples/mujoco_rfb: MuJoCo linked to librfbsim)
// and x11 (an unmodified X11 program, glxgears, under TigerVNC's Xvnc, started by rfbsim_x11_session); and video,
// a watcher's session of the video condition (sim_rfb --replay of a lab session recorded first, with a client
// watching and nobody pressing keys, as in the sim_rfb row).
//
// For each kind a sim_manager of its own serves the sessions; for each of R runs:
//   1. GET /start with a fresh uid, and at once a client (libvncclient behind a WsRfbBridge, as the participant
//      page opens it) on the redirect's WebSocket; start-up to first frame = from sending /start to the first
//      complete framebuffer update that shows a picture (not one flat colour: Xvnc's empty display comes
//      first), and the CPU the session's processes used up to then;
//   2. after a warm-up of one second, S seconds of the client taking updates, with the session's process group
//      (every process whose group is the index row's pid: the one program, or launcher + Xvnc + program) read
//      from /proc before and after: CPU cores = CPU seconds / wall seconds, its RSS and its process count at the
//      end, the updates per second the client saw, and the manager's own CPU (its relay) over the same seconds;
//   3. the session ended through the admin API, and gone, before the next run.
// A kind whose program is missing is skipped with a line saying so. Every number is printed; nothing passes or
// fails. The client runs in this thread, on the same machine, and its own CPU (JPEG decoding) is not counted.
// A failed kind is reported and the others still run; the exit status is then 1.
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_cli.hpp"
#include "bench_util.hpp"
#include "manager_probe.hpp"
#include "manager_process.hpp"
#include "manager_session.hpp"
#include "rfb_test_client.hpp"
#include "session_group.hpp"
#include "ws_rfb_bridge.hpp"

namespace {

namespace bench = rfbsim::bench;
using bench::Clock;
using rfbsim::test::IndexRow;
using rfbsim::test::ManagerUnderTest;
using std::chrono::milliseconds;

constexpr auto kFirstFrameTimeout = milliseconds(60000);  // /start to the first update (x11 starts two programs)
constexpr auto kEndTimeout = milliseconds(20000);         // admin end to the index's final state
constexpr auto kWarmUp = milliseconds(1000);  // after the first frame: start-up's last work stays out of the window

struct Options {
  bench::Size size{640, 480};
  int runs = 5;
  int seconds = 10;
  std::vector<std::string> kinds = {"sim_rfb", "video", "rfb", "x11"};
  std::string manager = rfbsim::test::sim_manager_path();  // $RFBSIM_SIM_MANAGER, or the one built here
  std::string mujoco = RFBSIM_BENCH_MUJOCO_RFB;             // "" where the build found no MuJoCo
  std::string x11_program = "/usr/bin/glxgears";
  std::string xvnc = "/usr/bin/Xvnc";
  std::string log = (std::filesystem::temp_directory_path() / "rfbsim_bench_session_kinds.log").string();
};

Options parse_options(int argc, char** argv) {
  Options o;
  bench::CommandLine cli(
      "bench_session_kinds",
      "Per session kind at one picture size: start-up to first frame through sim_manager, then S seconds of a\n"
      "client taking updates while the session's process group is read from /proc (CPU cores, RSS, processes),\n"
      "R runs each. Kinds: sim_rfb (the lab scenario), video (a watcher: sim_rfb --replay of a lab session\n"
      "recorded first), rfb (mujoco_rfb), x11 (the X11 program under Xvnc).\n"
      "sim_manager's and its sessions' output go to the log.");
  cli.size("--size", o.size, "the picture's size, 160x120 .. 3840x2160")
      // sim_rfb's and mujoco_rfb's own bounds, so that a size one of them refuses fails here, clearly.
      ->check(bench::satisfies(
          [](const std::string& text) {
            const std::vector<bench::Size> sizes = bench::parse_sizes(text);
            return sizes.size() == 1 && sizes[0].width >= 160 && sizes[0].width <= 3840 && sizes[0].height >= 120 &&
                   sizes[0].height <= 2160;
          },
          "one WIDTHxHEIGHT in 160x120 .. 3840x2160"));
  cli.number("--runs", o.runs, 1, 100, "runs per kind");
  cli.number("--seconds", o.seconds, 1, 600, "seconds measured per run");
  cli.list("--kinds", o.kinds, bench::item_of({"sim_rfb", "video", "rfb", "x11"}, "--kinds"),
           "session kinds: sim_rfb, video, rfb, x11");
  cli.text("--manager", o.manager, "the sim_manager to run");
  cli.app().add_option("--mujoco", o.mujoco, "the mujoco_rfb to run (default: the one built here)")->type_name("TEXT");
  cli.text("--x11-program", o.x11_program, "the X11 program");
  cli.text("--xvnc", o.xvnc, "TigerVNC's Xvnc");
  cli.text("--log", o.log, "where the output goes");
  cli.parse(argc, argv);
  return o;
}

// ----------------------------------------------------------------------------------------------------------
// One kind: how its manager is started and its links look
// ----------------------------------------------------------------------------------------------------------

struct KindPlan {
  std::string kind;
  std::string program;             // what the table names
  std::string missing;             // why the kind cannot run here ("" when it can)
  std::vector<std::string> flags;  // sim_manager's flags beyond the data folder and port
  std::string link_extra;          // appended to "uid=..." in /start
  std::chrono::seconds source{0};  // video: how long a walker's session to record first, for every run to watch
};

bool is_executable(const std::string& path) { return !path.empty() && ::access(path.c_str(), X_OK) == 0; }

// Adds `--session-arg A` for each of `args`.
void add_session_args(std::vector<std::string>& flags, const std::vector<std::string>& args) {
  for (const std::string& arg : args) flags.insert(flags.end(), {"--session-arg", arg});
}

KindPlan plan_for(const std::string& kind, const Options& o) {
  KindPlan plan;
  plan.kind = kind;
  // One session at a time, no per-address limits (every link comes from loopback), an hour per session.
  plan.flags = rfbsim::test::without_abuse_limits(
      {"--max-sessions", "1", "--admin-token", bench::kBenchAdminToken, "--max-duration-s", "3600"});
  const std::string width = std::to_string(o.size.width);
  const std::string height = std::to_string(o.size.height);
  if (kind == "sim_rfb" || kind == "video") {
    // The sim_rfb beside the manager (its default session program) at its default 30 fps.
    plan.program = "sim_rfb --scenario lab";
    if (!is_executable(o.manager)) plan.missing = "sim_manager not found at " + o.manager;
    plan.flags.insert(plan.flags.end(), {"--scenarios", "lab"});
    add_session_args(plan.flags, {"--width", width, "--height", height});
    plan.link_extra = "&scenario=lab";
    if (kind == "video") {
      // Every run watches the one recording: long enough for the first frame, the warm-up and the window.
      plan.program = "sim_rfb --replay (lab)";
      plan.flags.insert(plan.flags.end(), {"--yoke-max-viewers", "1000"});
      plan.link_extra += "&condition=video";
      plan.source = std::chrono::seconds(o.seconds + 10);
    }
  } else if (kind == "rfb") {
    plan.program = std::filesystem::path(o.mujoco).filename().string();
    if (!is_executable(o.mujoco)) {
      plan.program = "mujoco_rfb";
      plan.missing = o.mujoco.empty() ? "mujoco_rfb was not built (no MuJoCo found; or pass --mujoco PATH)"
                                      : "mujoco_rfb not found at " + o.mujoco;
    }
    plan.flags.insert(plan.flags.end(), {"--session-kind", "rfb", "--session-command", o.mujoco});
    add_session_args(plan.flags,
                     {"--port", "{port}", "--bind", "127.0.0.1", "--rfb-only", "--width", width, "--height", height});
  } else {
    const std::string name = std::filesystem::path(o.x11_program).filename().string();
    plan.program = "Xvnc + " + name;
    if (!is_executable(o.xvnc)) plan.missing = "Xvnc not found at " + o.xvnc + " (tigervnc-standalone-server)";
    if (!is_executable(o.x11_program)) plan.missing = o.x11_program + " not found";
    plan.flags.insert(plan.flags.end(), {"--session-kind", "x11", "--session-command", o.x11_program,
                                         "--x11-geometry", o.size.text(), "--x11-xvnc", o.xvnc});
    // The window fills the display (there is no window manager to place it).
    add_session_args(plan.flags, {"-geometry", o.size.text() + "+0+0"});
  }
  return plan;
}

// ----------------------------------------------------------------------------------------------------------
// One run: a link, its first frame, S seconds watched
// ----------------------------------------------------------------------------------------------------------

struct RunResult {
  double first_update_ms = 0.0;  // /start sent -> first complete update at the client
  double first_ms = 0.0;         // /start sent -> first update after which the picture shows something
  double startup_cpu_s = 0.0;    // the group's CPU time at the first picture
  double cores = 0.0;            // the group's CPU seconds per wall second over the window
  double rss_mib = 0.0;          // the group's VmRSS at the window's end
  int processes = 0;             // the group's processes at the window's end
  double fps = 0.0;              // updates per second at the client over the window
  double relay_cores = 0.0;      // sim_manager's CPU seconds per wall second over the window
  std::string picture;           // the client's framebuffer size, WxH
  std::string names;             // the group's members with their cores and RSS
};

// Whether the picture shows something: more than 1 % of its pixels differ clearly (|dR|+|dG|+|dB| > 48) from
// its top-left pixel. Xvnc serves its empty black display before the program has mapped and drawn its window,
// so the first update alone would time Xvnc's start, not the program's.
bool shows_content(const rfbsim::FrameView& frame) {
  const std::uint8_t* corner = frame.row(0);
  std::size_t differing = 0;
  for (int y = 0; y < frame.height; ++y) {
    const std::uint8_t* p = frame.row(y);
    for (int x = 0; x < frame.width; ++x, p += 4) {
      differing += std::abs(p[0] - corner[0]) + std::abs(p[1] - corner[1]) + std::abs(p[2] - corner[2]) > 48 ? 1U : 0U;
    }
  }
  return differing * 100 > static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height);
}

// What an answer's body says in one line: an HTML page's <title>, else the body's first 200 characters.
std::string page_gist(const std::string& body) {
  const std::size_t open = body.find("<title>");
  const std::size_t close = body.find("</title>");
  if (open != std::string::npos && close != std::string::npos && close > open) {
    return body.substr(open + 7, close - open - 7);
  }
  return body.substr(0, 200);
}

RunResult run_once(const ManagerUnderTest& manager, const KindPlan& plan, const Options& o, int index) {
  RunResult r;
  const std::string uid = "bench-kinds-" + std::to_string(::getpid()) + "-" + plan.kind + "-" + std::to_string(index);

  // 1. Start-up to first frame. The page opens the WebSocket right away; the manager holds it until the session
  // is ready, so the RFB handshake below completes once the program serves.
  const auto t0 = Clock::now();
  const rfbsim::test::net::HttpResponse response = manager.start("uid=" + uid + plan.link_extra);
  const std::string token = rfbsim::test::token_from_redirect(response);
  if (token.empty()) {
    throw std::runtime_error("/start for " + uid + " answered " + std::to_string(response.status) + ": " +
                             page_gist(response.body));
  }
  std::optional<IndexRow> row;
  {
    const rfbsim::test::WsRfbBridge bridge(manager.ws_url(token), manager.origin());
    rfbsim::test::RfbTestClient client("127.0.0.1", bridge.port());
    std::uint64_t looked_at = 0;
    const bool shown = client.pump_until(
        [&] {
          if (client.updates() == looked_at) return false;
          if (looked_at == 0) r.first_update_ms = bench::ms_between(t0, Clock::now());
          looked_at = client.updates();
          return shows_content(client.frame());
        },
        kFirstFrameTimeout - std::chrono::duration_cast<milliseconds>(Clock::now() - t0));
    if (!shown) {
      throw std::runtime_error("no picture for " + uid + " within " + std::to_string(kFirstFrameTimeout.count()) +
                               " ms (" + std::to_string(client.updates()) + " updates, all one colour)");
    }
    r.first_ms = bench::ms_between(t0, Clock::now());
    r.picture = std::to_string(client.width()) + "x" + std::to_string(client.height());
    row = bench::wait_for_row(manager, token, [](const IndexRow& x) { return x.pid > 0; }, kFirstFrameTimeout,
                              "got a pid");
    const auto group = static_cast<pid_t>(row->pid);
    r.startup_cpu_s = bench::group_cpu_s(bench::group_members(group));

    // 2. The window, after a warm-up: the group and the manager read before and after while this thread takes
    // the updates, as fast as they come.
    const auto never = [] { return false; };
    client.pump_until(never, kWarmUp);
    const auto before = bench::group_members(group);
    const double manager_before = bench::sample_process(manager.pid()).cpu_s;
    const std::uint64_t updates_before = client.updates();
    const auto t_before = Clock::now();
    client.pump_until(never, std::chrono::seconds(o.seconds));
    const auto after = bench::group_members(group);
    const double manager_after = bench::sample_process(manager.pid()).cpu_s;
    const double wall_s = bench::ms_between(t_before, Clock::now()) / 1000.0;
    if (!client.connected()) throw std::runtime_error("the client of " + uid + " lost its connection");
    if (after.empty()) throw std::runtime_error("the session of " + uid + " has no process left");
    r.cores = bench::group_cpu_between(before, after) / wall_s;
    r.rss_mib = bench::group_rss_mib(after);
    r.processes = static_cast<int>(after.size());
    r.names = bench::group_breakdown(before, after, wall_s);
    r.fps = static_cast<double>(client.updates() - updates_before) / wall_s;
    r.relay_cores = (manager_after - manager_before) / wall_s;
  }  // the client disconnects

  // 3. End it, and wait until it is gone, so that the next run starts on a quiet manager.
  bench::end_session(manager, row->id);
  bench::wait_for_row(manager, token, [](const IndexRow& x) { return !bench::is_live_state(x.state); }, kEndTimeout,
                      "ended");
  return r;
}

// video: the walker's session every run watches: a lab session with a client taking updates for plan.source
// (nobody presses keys: the crowd and the robot move), then ended by the researcher.
void record_source(const ManagerUnderTest& manager, const KindPlan& plan) {
  const std::string uid = "bench-kinds-" + std::to_string(::getpid()) + "-source";
  const std::string token = rfbsim::test::token_from_redirect(manager.start("uid=" + uid + "&scenario=lab"));
  if (token.empty()) throw std::runtime_error("/start of the source session " + uid + " failed");
  {
    const rfbsim::test::WsRfbBridge bridge(manager.ws_url(token), manager.origin());
    rfbsim::test::RfbTestClient client("127.0.0.1", bridge.port());
    client.pump_until([] { return false; }, plan.source);
    if (client.updates() == 0) throw std::runtime_error("the source session " + uid + " showed nothing");
  }
  const IndexRow row = bench::wait_for_row(manager, token, [](const IndexRow& x) { return !x.spent_at.empty(); },
                                           kEndTimeout, "spent");
  bench::end_session(manager, row.id);
  bench::wait_for_row(manager, token, [](const IndexRow& x) { return !bench::is_live_state(x.state); }, kEndTimeout,
                      "ended");
}

std::vector<RunResult> run_kind(const KindPlan& plan, const Options& o) {
  rfbsim::test::TempDir data("rfbsim-bench-kinds");
  rfbsim::test::ManagerOptions how;
  how.program = o.manager;
  how.stop_signal = SIGTERM;  // the manager ends its sessions itself
  how.stop_timeout = std::chrono::milliseconds(30000);
  how.poll_interval = std::chrono::milliseconds(5);
  const bench::StderrToFile redirect(o.log);
  ManagerUnderTest manager(data.path(), plan.flags, how);
  if (plan.source.count() > 0) record_source(manager, plan);
  std::vector<RunResult> results;
  for (int i = 0; i < o.runs; ++i) results.push_back(run_once(manager, plan, o, i));
  return results;
}

// ----------------------------------------------------------------------------------------------------------
// The table
// ----------------------------------------------------------------------------------------------------------

// The median of one field over the runs.
template <typename Field>
double median_of(const std::vector<RunResult>& runs, Field field) {
  std::vector<double> values;
  for (const RunResult& r : runs) values.push_back(static_cast<double>(r.*field));
  return bench::summarize(values).p50;
}

// "p50 (min-max)" of the first-frame times, whole milliseconds.
std::string first_frame_cell(const std::vector<RunResult>& runs) {
  std::vector<double> values;
  for (const RunResult& r : runs) values.push_back(r.first_ms);
  const auto [low, high] = std::minmax_element(values.begin(), values.end());
  return bench::fixed(bench::summarize(values).p50, 0) + " (" + bench::fixed(*low, 0) + "-" + bench::fixed(*high, 0) +
         ")";
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  try {
    options = parse_options(argc, argv);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "bench_session_kinds: %s (--help shows the usage)\n", error.what());
    return 2;
  }

  std::printf("# bench_session_kinds: %s, %d run(s) per kind, %d s measured after a %lld ms warm-up\n",
              options.size.text().c_str(), options.runs, options.seconds,
              static_cast<long long>(kWarmUp.count()));
  std::printf("# machine: %s, load average %s at the start; log: %s\n", bench::cpu_description().c_str(),
              bench::load_average().c_str(), options.log.c_str());

  bench::Table table({"kind", "program", "picture", "processes", "first update ms", "first picture ms p50 (min-max)",
                      "start-up CPU s", "CPU cores", "RSS MiB", "client fps", "manager cores"},
                     3);
  std::vector<std::string> notes;
  int failed = 0;
  for (const std::string& kind : options.kinds) {
    const KindPlan plan = plan_for(kind, options);
    if (!plan.missing.empty()) {
      notes.push_back(kind + ": skipped: " + plan.missing);
      continue;
    }
    std::fprintf(stderr, "bench_session_kinds: %s (%s), %d run(s)...\n", kind.c_str(), plan.program.c_str(),
                 options.runs);
    try {
      const std::vector<RunResult> runs = run_kind(plan, options);
      const auto median = [&](auto field, int decimals) { return bench::fixed(median_of(runs, field), decimals); };
      table.add_row({kind, plan.program, runs.back().picture, median(&RunResult::processes, 0),
                     median(&RunResult::first_update_ms, 0), first_frame_cell(runs),
                     median(&RunResult::startup_cpu_s, 2), median(&RunResult::cores, 2), median(&RunResult::rss_mib, 0),
                     median(&RunResult::fps, 1), median(&RunResult::relay_cores, 3)});
      notes.push_back(kind + ": the last run's processes: " + runs.back().names);
    } catch (const std::exception& error) {
      notes.push_back(kind + ": failed: " + error.what() + " (see " + options.log + ")");
      ++failed;
    }
  }
  table.print();
  std::printf("Medians over the runs. First update / first picture: from sending /start to the client's first "
              "complete update / to the first that shows more than one colour. Start-up CPU s: the session's CPU "
              "time at its first picture. CPU cores, RSS and processes: the session's process group over the "
              "window; manager cores: sim_manager (its relay) over the same seconds; client fps: complete updates "
              "per second seen through the relay.\n");
  for (const std::string& note : notes) std::printf("%s\n", note.c_str());
  std::printf("# load average %s at the end\n", bench::load_average().c_str());
  return failed == 0 ? 0 : 1;
}
