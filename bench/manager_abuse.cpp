// SPDX-License-Identifier: GPL-2.0-or-later
// The abuse run's phases, its participant and its report; see manager_abuse.hpp.
#include "manager_abuse.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <functional>
#include <thread>

#include "bench_util.hpp"
#include "manager_clients.hpp"
#include "manager_session.hpp"

namespace rfbsim::bench {

namespace {

using std::chrono::milliseconds;

constexpr auto kFirstFrameTimeout = milliseconds(30000);
constexpr auto kAbuseEndTimeout = milliseconds(30000);

// The /metrics lines the report shows.
const std::vector<std::string> kCounters = {
    "rfbsim_rejections_total{reason=\"rate_limited\"}",    "rfbsim_rejections_total{reason=\"connection_limit\"}",
    "rfbsim_rejections_total{reason=\"unspent_limit\"}",   "rfbsim_rejections_total{reason=\"busy\"}",
    "rfbsim_accept_errors_total",                          "rfbsim_connections",
    "rfbsim_connection_addresses",                         "rfbsim_session_starts_total"};

// This process's user + system CPU time, seconds.
double own_cpu_s() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) / 1e6; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

// One participant: link, first frame, frames over `seconds`, then the session ended through the admin API.
ParticipantRun participant(const test::ManagerUnderTest& manager, const std::string& scenario, int seconds,
                           const std::string& uid) {
  ParticipantRun run;
  std::string token;
  try {
    const auto t0 = Clock::now();
    token = start_session(manager, uid, scenario);
    WatchedClient client(manager.ws_url(token), manager.origin(), false);
    client.start();
    const auto deadline = t0 + kFirstFrameTimeout;
    while (client.updates() == 0 && client.connected() && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    if (client.updates() == 0) throw std::runtime_error("no first frame within 30 s");
    run.first_ms = ms_between(t0, Clock::now());
    const std::uint64_t before = client.updates();
    const auto from = Clock::now();
    std::this_thread::sleep_for(std::chrono::seconds(seconds));
    run.fps = static_cast<double>(client.updates() - before) / (ms_between(from, Clock::now()) / 1000.0);
    client.stop();
    if (!client.connected()) throw std::runtime_error("the connection was lost while counting frames");
  } catch (const std::exception& error) {
    run.error = error.what();
  }
  // Free the slot, and wait until it is free, whatever happened above.
  if (!token.empty()) {
    try {
      if (const auto row = manager.row_for_token(token); row && is_live_state(row->state)) end_session(manager, row->id);
      wait_for_row(manager, token, [](const test::IndexRow& x) { return !is_live_state(x.state); }, kAbuseEndTimeout,
                   "ended");
    } catch (const std::exception& error) {
      if (run.error.empty()) run.error = error.what();
    }
  }
  return run;
}

// Adds one participant run to `phase`, with what the manager and this process spent while `work` ran.
void timed_run(const test::ManagerUnderTest& manager, AbusePhase& phase, const std::function<ParticipantRun()>& work) {
  const auto began = Clock::now();
  const double manager_cpu = sample_process(manager.pid()).cpu_s;
  const double bench_cpu = own_cpu_s();
  phase.runs.push_back(work());
  phase.manager_after = sample_process(manager.pid());
  phase.manager_cpu_s += phase.manager_after.cpu_s - manager_cpu;
  phase.bench_cpu_s += own_cpu_s() - bench_cpu;
  phase.seconds += ms_between(began, Clock::now()) / 1000.0;
}

// Ends the sessions the storm started (the unseen ones would otherwise hold their slots until the idle
// timeout, into the next idle run) and waits until they are gone.
void end_storm_sessions(const test::ManagerUnderTest& manager) {
  for (const test::IndexRow& row : manager.index_rows()) {
    if (row.uid.rfind("storm-", 0) != 0 || !is_live_state(row.state)) continue;
    try {
      end_session(manager, row.id);
    } catch (const std::exception&) {
      // It ended by itself between the look and the request.
    }
    wait_for_row(manager, row.token, [](const test::IndexRow& x) { return !is_live_state(x.state); }, kAbuseEndTimeout,
                 "ended");
  }
}

void add_counts(AbuserCounts& total, const AbuserCounts& more) {
  total.connects += more.connects;
  total.connect_errors += more.connect_errors;
  total.closed_by_server += more.closed_by_server;
  total.open_now = more.open_now;
  total.open_peak = std::max(total.open_peak, more.open_peak);
  total.storm_requests += more.storm_requests;
  for (const auto& [status, count] : more.storm_status) total.storm_status[status] += count;
}

// Medians of the runs that got their frames.
Summary first_frames(const AbusePhase& phase) {
  std::vector<double> samples;
  for (const ParticipantRun& r : phase.runs) {
    if (r.error.empty()) samples.push_back(r.first_ms);
  }
  return summarize(samples);
}

Summary frame_rates(const AbusePhase& phase) {
  std::vector<double> samples;
  for (const ParticipantRun& r : phase.runs) {
    if (r.error.empty()) samples.push_back(r.fps);
  }
  return summarize(samples);
}

}  // namespace

AbuseResult run_abuse(const test::ManagerUnderTest& manager, const std::string& scenario, const AbuseOptions& options,
                      long descriptor_limit) {
  AbuseResult result;
  result.descriptor_limit = descriptor_limit;
  AbuserOptions how;
  how.port = manager.port();
  how.from = options.from;
  how.half_open = options.half_open;
  how.scenario = scenario;
  how.storm_per_second = options.storm_per_second;
  const std::string prefix = "bench-abuse-" + std::to_string(::getpid()) + "-";

  // Idle and abused runs alternate, so that other work on a shared machine weighs on both alike.
  for (int i = 0; i < options.repetitions; ++i) {
    // (a) Nothing else talks to the manager.
    timed_run(manager, result.idle, [&] {
      return participant(manager, scenario, options.seconds, prefix + "idle-" + std::to_string(i));
    });
    // (b) The same while the abuser runs; its counters and the manager's are read before it stops.
    timed_run(manager, result.abused, [&] {
      Abuser abuser(how);
      std::this_thread::sleep_for(std::chrono::seconds(options.ramp_seconds));
      ParticipantRun run = participant(manager, scenario, options.seconds, prefix + "abused-" + std::to_string(i));
      add_counts(result.abuser, abuser.counts());
      if (i + 1 == options.repetitions) {
        for (const std::string& name : kCounters) result.counters[name] = manager.metric(name);
      }
      return run;
    });
    end_storm_sessions(manager);
  }
  return result;
}

void print_abuse(const AbuseResult& result, const AbuseOptions& options) {
  std::printf("### Abuse: a participant on an idle manager, then while %s holds %d idle half-open sockets and "
              "hammers /start\n\n",
              options.from.c_str(), options.half_open);
  std::printf("The participant comes from 127.0.0.1 (WsRfbBridge cannot pick its source address), the abuser from "
              "%s; sim_manager runs with its shipped abuse limits and inherits RLIMIT_NOFILE %ld. Each run: GET "
              "/start, libvncclient through the relay, first frame, frames over %d s, admin end.\n\n",
              options.from.c_str(), result.descriptor_limit, options.seconds);
  Table runs({"phase", "run", "first frame ms", "fps", "error"}, 2);
  const auto add_runs = [&](const AbusePhase& phase, const char* name) {
    for (std::size_t i = 0; i < phase.runs.size(); ++i) {
      const ParticipantRun& r = phase.runs[i];
      runs.add_row({name, std::to_string(i + 1), r.error.empty() ? fixed(r.first_ms, 0) : "-",
                    r.error.empty() ? fixed(r.fps, 1) : "-", r.error.empty() ? "" : r.error});
    }
  };
  add_runs(result.idle, "(a) idle");
  add_runs(result.abused, "(b) abused");
  runs.print();

  const Summary idle_first = first_frames(result.idle), abused_first = first_frames(result.abused);
  const Summary idle_fps = frame_rates(result.idle), abused_fps = frame_rates(result.abused);
  std::printf("\n");
  Table summary({"median", "(a) idle", "(b) abused", "(b) - (a)", "(b) / (a)", "target"}, 1);
  summary.add_row({"first frame ms", fixed(idle_first.p50, 0), fixed(abused_first.p50, 0),
                   fixed(abused_first.p50 - idle_first.p50, 0), "", "(b) - (a) <= 1000"});
  summary.add_row({"fps", fixed(idle_fps.p50, 1), fixed(abused_fps.p50, 1), "",
                   idle_fps.p50 > 0 ? fixed(abused_fps.p50 / idle_fps.p50, 2) : "-", "(b) / (a) >= 0.90"});
  summary.add_row({"sim_manager CPU % of one core", fixed(100.0 * result.idle.manager_cpu_s / result.idle.seconds, 0),
                   fixed(100.0 * result.abused.manager_cpu_s / result.abused.seconds, 0), "", "", ""});
  summary.add_row({"this process CPU % (client; + abuser in b)",
                   fixed(100.0 * result.idle.bench_cpu_s / result.idle.seconds, 0),
                   fixed(100.0 * result.abused.bench_cpu_s / result.abused.seconds, 0), "", "", ""});
  summary.add_row({"sim_manager RSS MiB / fds at the end", fixed(result.idle.manager_after.rss_mib, 1) + " / " +
                   std::to_string(result.idle.manager_after.descriptors),
                   fixed(result.abused.manager_after.rss_mib, 1) + " / " +
                   std::to_string(result.abused.manager_after.descriptors), "", "", ""});
  summary.print();

  const AbuserCounts& a = result.abuser;
  std::printf("\nThe abuser, over %d runs of %d s + a %d s ramp each: %llu half-open connects (%llu failed), %llu closed by the "
              "manager, %llu open at the last look, %llu at most at once; %llu /start requests:",
              options.repetitions, options.seconds, options.ramp_seconds, static_cast<unsigned long long>(a.connects),
              static_cast<unsigned long long>(a.connect_errors), static_cast<unsigned long long>(a.closed_by_server),
              static_cast<unsigned long long>(a.open_now), static_cast<unsigned long long>(a.open_peak),
              static_cast<unsigned long long>(a.storm_requests));
  for (const auto& [status, count] : a.storm_status) {
    std::printf(" %s %llu", status < 0 ? "no answer" : std::to_string(status).c_str(),
                static_cast<unsigned long long>(count));
  }
  std::printf("\nsim_manager's /metrics at the end of (b) (counters since it started; -1 = absent):\n");
  for (const auto& [name, value] : result.counters) std::printf("  %s %.0f\n", name.c_str(), value);
  std::printf("\n");
}

}  // namespace rfbsim::bench
