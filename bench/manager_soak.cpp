// SPDX-License-Identifier: GPL-2.0-or-later
// The soak's scheduler, its session workers and its table; see manager_soak.hpp.
#include "manager_soak.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <exception>
#include <list>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "bench_util.hpp"
#include "manager_clients.hpp"
#include "manager_session.hpp"

namespace rfbsim::bench {

namespace {

using std::chrono::milliseconds;

constexpr auto kReadyTimeout = milliseconds(30000);  // /start to the first update
constexpr auto kSoakEndTimeout = milliseconds(30000);    // admin end to a final state
constexpr std::size_t kKeptErrors = 5;

// What the workers share with the scheduler.
struct SoakTally {
  std::mutex mutex;
  std::map<std::string, int> final_states;  // under mutex
  std::vector<std::string> errors;          // under mutex
  std::atomic<int> started{0};
  std::atomic<int> finished{0};
  std::atomic<int> failed{0};
  std::atomic<std::uint64_t> updates{0};

  void fail(const std::string& what) {
    ++failed;
    const std::lock_guard lock(mutex);
    if (errors.size() < kKeptErrors) errors.push_back(what);
  }
};

// One session's whole life, on a worker thread: start, watch, disconnect, end (admin or idle), final state.
void soak_session(const test::ManagerUnderTest& manager, const std::string& scenario, const SoakOptions& options,
                  int number, bool leave_to_idle, SoakTally& tally) {
  const std::string uid = "bench-soak-" + std::to_string(::getpid()) + "-" + std::to_string(number);
  try {
    const std::string token = start_session(manager, uid, scenario);
    ++tally.started;
    {
      WatchedClient client(manager.ws_url(token), manager.origin(), false);
      client.start();
      // Frames for watch_seconds after the first one (the first takes the session's start-up).
      const auto deadline = Clock::now() + kReadyTimeout;
      while (client.updates() == 0 && client.connected() && Clock::now() < deadline) {
        std::this_thread::sleep_for(milliseconds(20));
      }
      if (client.updates() == 0) throw std::runtime_error("no first update for " + uid);
      std::this_thread::sleep_for(std::chrono::seconds(options.watch_seconds));
      client.stop();
      if (!client.connected()) throw std::runtime_error("the client of " + uid + " lost its connection");
      tally.updates += client.updates();
    }  // the bridge closes the WebSocket here: the participant leaves

    const test::IndexRow row = wait_for_row(
        manager, token, [](const test::IndexRow& x) { return !x.ready_at.empty(); }, kReadyTimeout, "became ready");
    if (!leave_to_idle) end_session(manager, row.id);
    const auto end_timeout = kSoakEndTimeout + (leave_to_idle ? std::chrono::seconds(kSoakIdleTimeoutS) : milliseconds(0));
    const test::IndexRow last = wait_for_row(
        manager, token, [](const test::IndexRow& x) { return !is_live_state(x.state); }, end_timeout, "ended");
    const std::lock_guard lock(tally.mutex);
    ++tally.final_states[last.state];
  } catch (const std::exception& error) {
    tally.fail(error.what());
  }
  ++tally.finished;
}

// A worker thread and whether it has returned.
struct Worker {
  std::shared_ptr<std::atomic<bool>> done = std::make_shared<std::atomic<bool>>(false);
  std::thread thread;
};

}  // namespace

SoakResult run_soak(const test::ManagerUnderTest& manager, const std::string& scenario, const SoakOptions& options) {
  SoakTally tally;
  SoakResult result;
  std::list<Worker> workers;
  const auto began = Clock::now();
  auto stop_starting = began + milliseconds(static_cast<std::int64_t>(options.minutes * 60000.0));
  const auto interval = milliseconds(60000 / options.sessions_per_minute);
  auto next_start = began;
  auto next_sample = began;
  int launched = 0;

  std::string manager_gone;  // sampling failed: the manager exited
  const auto sample = [&] {
    if (!manager_gone.empty()) return;
    SoakSample s;
    s.at_s = ms_between(began, Clock::now()) / 1000.0;
    s.started = tally.started.load();
    s.finished = tally.finished.load();
    s.failed = tally.failed.load();
    s.in_flight = launched - s.finished;
    s.updates = tally.updates.load();
    try {
      s.manager = sample_process(manager.pid());
    } catch (const std::runtime_error& error) {
      // No new sessions; the workers fail fast and are joined before this is reported.
      manager_gone = error.what();
      stop_starting = Clock::now();
      return;
    }
    result.samples.push_back(s);
  };

  // One loop starts sessions at the planned pace (late when every slot is taken) and samples the manager.
  for (;;) {
    const auto now = Clock::now();
    for (auto it = workers.begin(); it != workers.end();) {
      if (it->done->load()) {
        it->thread.join();
        it = workers.erase(it);
      } else {
        ++it;
      }
    }
    if (now < stop_starting && now >= next_start && static_cast<int>(workers.size()) < options.max_sessions) {
      const int number = launched++;
      const bool leave_to_idle = options.idle_every > 0 && number % options.idle_every == options.idle_every - 1;
      Worker& worker = workers.emplace_back();
      worker.thread = std::thread([&manager, &scenario, &options, &tally, number, leave_to_idle, done = worker.done] {
        soak_session(manager, scenario, options, number, leave_to_idle, tally);
        *done = true;
      });
      next_start += interval;
    }
    if (now >= next_sample) {
      sample();
      next_sample += std::chrono::seconds(options.sample_seconds);
    }
    if (now >= stop_starting && workers.empty()) break;
    std::this_thread::sleep_for(milliseconds(50));
  }
  // The last sample once every session is over: what stays is what a quiet manager holds.
  sample();
  if (!manager_gone.empty()) throw std::runtime_error("sim_manager is gone (" + manager_gone + ")");
  result.seconds = ms_between(began, Clock::now()) / 1000.0;
  result.final_states = tally.final_states;
  result.errors = tally.errors;
  return result;
}

void print_soak(const SoakResult& result, const SoakOptions& options) {
  std::printf("### Soak: sessions through the relay for %.1f min (planned %d per minute, at most %d at once, "
              "%d s of frames each; one in %d left to the %d s idle timeout, the rest ended by the admin API)\n\n",
              options.minutes, options.sessions_per_minute, options.max_sessions, options.watch_seconds,
              options.idle_every, kSoakIdleTimeoutS);
  Table table({"t s", "started", "finished", "failed", "in flight", "updates", "RSS MiB", "fds", "CPU s"}, 0);
  for (const SoakSample& s : result.samples) {
    table.add_row({fixed(s.at_s, 0), std::to_string(s.started), std::to_string(s.finished), std::to_string(s.failed),
                   std::to_string(s.in_flight), std::to_string(s.updates), fixed(s.manager.rss_mib, 2),
                   std::to_string(s.manager.descriptors), fixed(s.manager.cpu_s, 1)});
  }
  table.print();
  if (result.samples.empty()) return;

  const SoakSample& first = result.samples.front();
  const SoakSample& last = result.samples.back();
  double peak_rss = 0.0;
  int peak_fds = 0;
  for (const SoakSample& s : result.samples) {
    peak_rss = std::max(peak_rss, s.manager.rss_mib);
    peak_fds = std::max(peak_fds, s.manager.descriptors);
  }
  // Growth after warm-up too: the first sessions fill allocator arenas and SQLite's page cache once.
  const auto warm = std::find_if(result.samples.begin(), result.samples.end(),
                                 [](const SoakSample& s) { return s.at_s >= 60.0; });
  std::printf("\nsessions %d started, %d failed, %llu updates relayed; final states:", last.started, last.failed,
              static_cast<unsigned long long>(last.updates));
  for (const auto& [state, count] : result.final_states) std::printf(" %s %d", state.c_str(), count);
  std::printf("\nsim_manager RSS first -> last %.2f -> %.2f MiB (growth %+.2f MiB, peak %.2f); descriptors %d -> %d "
              "(peak %d)\n",
              first.manager.rss_mib, last.manager.rss_mib, last.manager.rss_mib - first.manager.rss_mib, peak_rss,
              first.manager.descriptors, last.manager.descriptors, peak_fds);
  if (warm != result.samples.end() && &*warm != &last) {
    std::printf("from the first sample at >= 60 s (t %.0f s) to the last: RSS %+.2f MiB, descriptors %+d\n", warm->at_s,
                last.manager.rss_mib - warm->manager.rss_mib, last.manager.descriptors - warm->manager.descriptors);
  }
  std::printf("Target: RSS grows < 10 MB over a 30-minute soak of 300 sessions with relayed frames. The last row is "
              "taken after every session is over.\n");
  for (const std::string& error : result.errors) std::printf("failure: %s\n", error.c_str());
  std::printf("soak wall time %.1f s\n\n", result.seconds);
}

}  // namespace rfbsim::bench
