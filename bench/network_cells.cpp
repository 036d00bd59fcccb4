// SPDX-License-Identifier: GPL-2.0-or-later
// One bench_network cell: walk, press, count and time (see network_cells.hpp).
#include "network_cells.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rfbsim::bench {

namespace {

using std::chrono::milliseconds;

constexpr auto kPumpSlice = milliseconds(5);      // the loop looks at its clock at least this often (RfbTestClient: 20)
constexpr auto kAfterTurn = milliseconds(200);    // a turn's last pictures are in this long after its hold, seen
                                                  // from its first visible one (a picture behind in a queue moves on)

double seconds_between(Clock::time_point from, Clock::time_point to) { return ms_between(from, to) / 1000.0; }

}  // namespace

std::vector<double> CellResult::latencies(double from_s, double to_s) const {
  std::vector<double> out;
  for (const PressResult& p : presses) {
    if (!std::isnan(p.latency_ms) && p.at_s >= from_s && p.at_s < to_s) out.push_back(p.latency_ms);
  }
  return out;
}

int CellResult::timeouts() const {
  return static_cast<int>(std::count_if(presses.begin(), presses.end(),
                                        [](const PressResult& p) { return std::isnan(p.latency_ms); }));
}

CellResult run_cell(NetClient& client, CellPath& path, const CellPlan& plan, std::mt19937& rng) {
  StreamSampler sampler(path);
  std::uniform_real_distribution<double> spread(0.8, 1.2);
  const auto interval = [&] {
    return std::chrono::duration_cast<Clock::duration>(plan.press_every * spread(rng));
  };

  const auto start = Clock::now();
  const auto from = start + plan.warm_up;
  const auto nominal_end = from + plan.measure;
  // However presses go, the window stops here (a cell whose presses all time out still ends).
  const auto hard_end = nominal_end + plan.measure + plan.press_timeout * 4;
  client.send_key(plan.walk_key, true);

  CellResult r;
  bool started = false;          // the measured window has begun
  test::LinkStats at_from;       // the emulator's counters then
  std::uint64_t h264_from = 0;
  Clock::time_point last_arrival{};
  std::uint64_t seen = client.updates();

  // The press in progress: the key is held until release_at; pending until its picture shows or it times out.
  bool held = false;
  bool pending = false;
  Clock::time_point t0{};
  Clock::time_point release_at{};
  Clock::time_point next_press = start + interval();
  PictureCopy reference;
  PressResult press;
  const auto finish_press = [&](double latency_ms, Clock::time_point seen_at) {
    pending = false;
    press.latency_ms = latency_ms;
    if (t0 >= from) r.presses.push_back(std::move(press));
    press = PressResult{};
    // The next press waits for this turn to have shown in full, so that its reference is a walking picture.
    const auto clear = std::isnan(latency_ms) ? seen_at + kAfterTurn : seen_at + plan.turn_hold + kAfterTurn;
    next_press = std::max(t0 + interval(), clear);
  };

  Clock::time_point now = start;
  for (;;) {
    now = Clock::now();
    if (!started && now >= from) {
      started = true;
      path.link().reset_peaks();
      at_from = path.link().stats();
      h264_from = client.h264_bytes();
      last_arrival = now;
    }
    const bool enough = static_cast<int>(r.presses.size()) >= plan.presses;
    if ((started && !pending && !held && now >= nominal_end && enough) || now >= hard_end) break;

    // The turn key: release, press, give up.
    if (held && now >= release_at) {
      client.send_key(plan.turn_key, false);
      held = false;
    }
    if (!pending && !held && now >= next_press) {
      reference.assign(client.frame());
      t0 = Clock::now();
      client.send_key(plan.turn_key, true);
      held = true;
      pending = true;
      release_at = t0 + plan.turn_hold;
      press.at_s = seconds_between(from, t0);
    }
    if (pending && now - t0 > plan.press_timeout) finish_press(kNaN, now);

    // Updates: count them, and judge each against the press's reference.
    client.pump_until([&] { return client.updates() != seen; }, kPumpSlice);
    if (!client.connected()) throw std::runtime_error("the client lost its connection");
    if (client.updates() == seen) continue;
    const auto arrived = Clock::now();
    seen = client.updates();
    if (started) {
      ++r.updates;
      r.arrivals_s.push_back(seconds_between(from, arrived));
      r.max_gap_ms = std::max(r.max_gap_ms, ms_between(last_arrival, arrived));
      last_arrival = arrived;
    }
    if (pending && arrived - t0 < plan.rtt) {
      reference.assign(client.frame());  // cannot show the press yet: the walk's latest picture before it could
      if (plan.trace) press.trace.emplace_back(ms_between(t0, arrived), -1.0);
    } else if (pending) {
      const double mad = sampled_mad(client.frame(), reference.view());
      if (plan.trace) press.trace.emplace_back(ms_between(t0, arrived), mad);
      if (mad > plan.threshold) finish_press(ms_between(t0, arrived), arrived);
    }
  }

  if (held) client.send_key(plan.turn_key, false);
  client.send_key(plan.walk_key, false);
  const test::LinkStats at_end = path.link().stats();
  r.seconds = seconds_between(from, now);
  r.max_gap_ms = std::max(r.max_gap_ms, ms_between(last_arrival, now));
  r.bytes_down = at_end.down.bytes_delivered - at_from.down.bytes_delivered;
  r.h264_bytes = client.h264_bytes() - h264_from;
  r.decode_errors = client.decode_errors();
  r.max_queue_delay_ms = static_cast<double>(at_end.down.max_queue_delay.count()) / 1000.0;
  r.samples = sampler.finish(from);
  return r;
}

}  // namespace rfbsim::bench
