// SPDX-License-Identifier: GPL-2.0-or-later
#include "congestion_control.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <deque>

namespace {

using namespace std::chrono_literals;
using rfbsim::detail::CongestionControl;
using std::chrono::microseconds;
using TimePoint = CongestionControl::TimePoint;

constexpr std::uint64_t kPingBytes = 9;           // a Fence with an empty payload
constexpr std::uint64_t kFull = 5 * 1024 * 1024;  // an update larger than any window: always limited
const TimePoint t0 = TimePoint{} + 1h;

// A server's side of one connection on a fake clock: updates, each followed by its ping.
// The window's arithmetic as published (TigerVNC's scheme): the delays these tests state are queueing,
// so the update's own time on the path is not discounted here (the simulated links below discount it).
const CongestionControl::Options kPlainScheme{false};

struct Sender {
  CongestionControl cc{kPlainScheme};
  std::uint64_t position = 0;
  TimePoint t = t0;  // where the next period starts

  void update(TimePoint at, std::uint64_t bytes) {
    position += bytes;
    cc.update_position(at, position);
    position += kPingBytes;
    cc.sent_ping(at, position);
  }
  // One update at `at` whose ping is answered after `rtt`, before anything else happens.
  void exchange(TimePoint at, std::uint64_t bytes, microseconds rtt) {
    update(at, bytes);
    REQUIRE(cc.got_pong(at + rtt));
  }
  // One measurement period: three updates 10 ms apart from `t`, each answered after `rtt`; `t` ends
  // 1 ms after the last answer.
  void period(microseconds rtt, std::uint64_t bytes = kFull) {
    REQUIRE(rtt > 20ms);  // all three are written before the first answer
    for (int i = 0; i < 3; ++i) update(t + i * 10ms, bytes);
    for (int i = 0; i < 3; ++i) REQUIRE(cc.got_pong(t + i * 10ms + rtt));
    t += 20ms + rtt + 1ms;
  }
  // Leaves slow start at 50 ms base RTT with the window at 20480 (32768 * 50 / 80).
  void enter_steady_state() {
    period(50ms);
    period(80ms);
    REQUIRE_FALSE(cc.in_slow_start());
    REQUIRE(cc.window() == 20480);
  }
};

}  // namespace

TEST_CASE("a new connection starts in slow start with the initial window", "[congestion_control]") {
  CongestionControl cc;
  CHECK(cc.window() == CongestionControl::kInitialWindow);
  CHECK(cc.in_slow_start());
  CHECK(cc.in_flight(t0) == 0);
  CHECK_FALSE(cc.is_congested(t0));
  CHECK(cc.outstanding_pings() == 0);
  CHECK_FALSE(cc.base_rtt());
  CHECK_FALSE(cc.last_rtt());
  CHECK(cc.delivery_rate() == 0);
  CHECK_FALSE(cc.got_pong(t0));  // nothing was asked
}

TEST_CASE("pongs acknowledge pings in order", "[congestion_control]") {
  Sender s;
  s.update(t0, 1000);
  s.update(t0 + 40ms, 2000);
  CHECK(s.cc.in_flight(t0 + 40ms) == 3018);
  CHECK(s.cc.outstanding_pings() == 2);
  REQUIRE(s.cc.got_pong(t0 + 80ms));
  CHECK(s.cc.in_flight(t0 + 80ms) == 2009);
  CHECK(s.cc.last_rtt() == 80ms);
  REQUIRE(s.cc.got_pong(t0 + 90ms));
  CHECK(s.cc.in_flight(t0 + 90ms) == 0);
  CHECK(s.cc.last_rtt() == 50ms);
  CHECK(s.cc.outstanding_pings() == 0);
  CHECK_FALSE(s.cc.got_pong(t0 + 95ms));  // unasked: ignored
}

TEST_CASE("base RTT is the lowest RTT measured", "[congestion_control]") {
  Sender s;
  s.exchange(t0, 1000, 80ms);
  CHECK(s.cc.base_rtt() == 80ms);
  s.exchange(t0 + 90ms, 2000, 50ms);
  CHECK(s.cc.base_rtt() == 50ms);
  s.exchange(t0 + 150ms, 100, 70ms);
  CHECK(s.cc.last_rtt() == 70ms);
  CHECK(s.cc.base_rtt() == 50ms);
}

TEST_CASE("congested exactly when the bytes in flight fill the window", "[congestion_control]") {
  Sender s;
  s.update(t0, CongestionControl::kInitialWindow - kPingBytes - 1);
  CHECK_FALSE(s.cc.is_congested(t0));
  s.cc.update_position(t0, s.position + 1);  // a write without a ping still counts as in flight
  CHECK(s.cc.is_congested(t0));
  REQUIRE(s.cc.got_pong(t0 + 40ms));
  CHECK(s.cc.in_flight(t0 + 40ms) == 1);  // the unpinged byte
  CHECK_FALSE(s.cc.is_congested(t0 + 40ms));
}

TEST_CASE("slow start doubles per period until a 25 ms queue shows", "[congestion_control]") {
  Sender s;
  s.period(50ms);
  CHECK(s.cc.window() == 32768);
  CHECK(s.cc.delivery_rate() == 0);  // window-limited, but no queue: the pongs only echo our own rate
  s.period(60ms);                    // 10 ms of queue: still below 25
  CHECK(s.cc.window() == 65536);
  CHECK(s.cc.in_slow_start());
  s.period(75ms);  // 25 ms: back to the window that had no queue, then grow slowly
  CHECK(s.cc.window() == 65536 * 50 / 75);
  CHECK_FALSE(s.cc.in_slow_start());
}

TEST_CASE("pings written before a window change do not measure the new window", "[congestion_control]") {
  Sender s;
  for (int i = 0; i < 4; ++i) s.update(t0 + i * 10ms, kFull);
  for (int i = 0; i < 4; ++i) REQUIRE(s.cc.got_pong(t0 + i * 10ms + 50ms));
  CHECK(s.cc.window() == 32768);  // the fourth pong came after the change and was not counted
  s.exchange(t0 + 100ms, kFull, 50ms);
  s.exchange(t0 + 160ms, kFull, 50ms);
  CHECK(s.cc.window() == 32768);
  s.exchange(t0 + 220ms, kFull, 50ms);
  CHECK(s.cc.window() == 65536);
}

TEST_CASE("a delay spike scales the window by baseRTT / minRTT", "[congestion_control]") {
  Sender s;
  SECTION("in slow start") {
    s.period(50ms);
    s.period(200ms);  // 150 ms of queue: > 100 and > 25
    CHECK(s.cc.window() == 8192);
    CHECK_FALSE(s.cc.in_slow_start());
  }
  SECTION("a long path needs more than half its RTT on top to count as a spike") {
    s.period(300ms);
    s.period(340ms);  // leaves slow start: 32768 * 300 / 340
    REQUIRE(s.cc.window() == 28912);
    s.period(420ms);  // 120 ms: > 100 ms but not > 150 ms, an ordinary long queue
    CHECK(s.cc.window() == 28912 - 4096);
    s.period(460ms);  // 160 ms: a spike
    CHECK(s.cc.window() == 24816 * 300 / 460);
  }
}

TEST_CASE("after slow start the window moves by +8, +4, 0 and -4 KiB", "[congestion_control]") {
  Sender s;
  s.enter_steady_state();
  s.period(52ms);
  CHECK(s.cc.window() == 20480 + 8192);
  s.period(60ms);
  CHECK(s.cc.window() == 28672 + 4096);
  s.period(80ms);  // 30 ms: hold
  CHECK(s.cc.window() == 32768);
  s.period(101ms);  // 51 ms: shrink
  CHECK(s.cc.window() == 32768 - 4096);
  CHECK_FALSE(s.cc.in_slow_start());
}

TEST_CASE("the window stays within 4 KiB and 4 MiB", "[congestion_control]") {
  Sender s;
  SECTION("floor") {
    s.enter_steady_state();
    for (int i = 0; i < 6; ++i) s.period(110ms);
    CHECK(s.cc.window() == CongestionControl::kMinWindow);
  }
  SECTION("ceiling") {
    for (int i = 0; i < 8; ++i) s.period(50ms);
    CHECK(s.cc.window() == CongestionControl::kMaxWindow);
    s.period(50ms);
    CHECK(s.cc.window() == CongestionControl::kMaxWindow);
  }
}

TEST_CASE("an app-limited sender does not grow the window", "[congestion_control]") {
  Sender s;
  for (int i = 0; i < 10; ++i) s.period(50ms, 1000);
  CHECK(s.cc.window() == CongestionControl::kInitialWindow);
  CHECK(s.cc.in_slow_start());
  s.enter_steady_state();
  for (int i = 0; i < 10; ++i) s.period(51ms, 1000);
  CHECK(s.cc.window() == 20480);
  s.period(110ms, 1000);  // but a long queue shrinks it all the same
  CHECK(s.cc.window() == 16384);
}

TEST_CASE("a long idle restarts slow start from at most 16 KiB", "[congestion_control]") {
  Sender s;
  s.period(50ms);
  s.period(50ms);
  REQUIRE(s.cc.window() == 65536);
  const TimePoint last_pong = s.t - 1ms;
  SECTION("idle for 100 ms (= 2 x baseRTT) is not yet idle") {
    s.update(last_pong + 100ms, 100);
    CHECK(s.cc.window() == 65536);
    CHECK(s.cc.base_rtt() == 50ms);
  }
  SECTION("idle for longer restarts") {
    s.update(last_pong + 101ms, 100);
    CHECK(s.cc.window() == CongestionControl::kInitialWindow);
    CHECK(s.cc.in_slow_start());
    CHECK_FALSE(s.cc.base_rtt());
  }
  SECTION("bytes still in flight are not idle") {
    s.update(last_pong, 100);
    s.update(last_pong + 500ms, 100);
    CHECK(s.cc.window() == 65536);
  }
}

TEST_CASE("idle is measured in baseRTTs on a long path and keeps a smaller window", "[congestion_control]") {
  Sender s;
  s.period(80ms);
  s.period(400ms);  // spike: 32768 * 80 / 400
  REQUIRE(s.cc.window() == 6553);
  const TimePoint last_pong = s.t - 1ms;
  s.exchange(last_pong + 160ms, 100, 80ms);  // 2 x 80 ms: not idle
  CHECK(s.cc.window() == 6553);
  CHECK_FALSE(s.cc.in_slow_start());
  s.update(last_pong + 240ms + 161ms, 100);
  CHECK(s.cc.window() == 6553);  // "at most" 16 KiB: a smaller window is kept
  CHECK(s.cc.in_slow_start());
}

TEST_CASE("delivery rate comes from queued, window-limited pongs, smoothed", "[congestion_control]") {
  Sender s;
  s.period(50ms);
  const TimePoint t = s.t;
  // Pongs 100 ms apart, 10 ms of queue each: the client received 100009 bytes in 0.1 s.
  s.exchange(t, 100000, 60ms);  // the first one only anchors the span
  CHECK(s.cc.delivery_rate() == 0);
  s.exchange(t + 100ms, 100000, 60ms);
  CHECK(s.cc.delivery_rate() == Approx(1000090.0));
  s.exchange(t + 200ms, 200000, 60ms);
  CHECK(s.cc.delivery_rate() == Approx(1000090.0 + 0.25 * 1000000.0));
  // A pong without a queue breaks the run: the next queued one anchors again, the estimate stays.
  s.exchange(t + 300ms, 100000, 50ms);
  s.exchange(t + 400ms, 100000, 60ms);
  CHECK(s.cc.delivery_rate() == Approx(1250090.0));
  s.exchange(t + 500ms, 100000, 60ms);
  CHECK(s.cc.delivery_rate() == Approx(1250090.0 - 0.25 * 250000.0));
}

namespace {

// A path with a fixed one-way delay each way and, towards the client, a FIFO bottleneck of `rate`
// bytes/s (0 = no cap). The bottleneck's buffer is bounded (kBufferBytes, a proxy's or a router's); a
// byte stream is never dropped, so bytes beyond it would wait in the sender's socket instead, with the
// same timing: the test watches the backlog to show congestion control keeps it far below the bound.
struct Path {
  static constexpr double kBufferBytes = 1 << 20;
  std::chrono::nanoseconds one_way;
  double rate;
  TimePoint drained{};  // when the bottleneck will have forwarded everything it holds

  // Bytes written at `at` arrive at the client at the returned time.
  TimePoint write(TimePoint at, std::uint64_t bytes) {
    if (rate == 0) return at + one_way;
    const std::chrono::duration<double> busy(static_cast<double>(bytes) / rate);
    drained = std::max(at, drained) + std::chrono::duration_cast<std::chrono::nanoseconds>(busy);
    return drained + one_way;
  }
  [[nodiscard]] double backlog(TimePoint at) const {
    return at >= drained ? 0 : rate * std::chrono::duration<double>(drained - at).count();
  }
};

struct Outcome {
  int offered = 0, sent = 0, unasked_pongs = 0;
  microseconds base_rtt{}, worst_rtt{};  // worst: after convergence
  double worst_backlog = 0;              // bytes at the bottleneck, after convergence
  double delivered_rate = 0;             // bytes/s arriving at the client after convergence
  double estimated_rate = 0;             // CongestionControl::delivery_rate() at the end
  double path_rate = 0;                  // CongestionControl::path_rate() at the end
};

constexpr std::uint64_t kFrameBytes = 40000;
constexpr auto kConverged = 10s;
constexpr auto kLength = 60s;

// A sender offering a 40 KB frame every 33 ms, pinging after each one sent. A frame that finds the
// window full is held and coalesces with later ones; a held frame goes out at the next frame tick or
// pong that finds room, as the server does. `controlled` = false sends every frame regardless.
Outcome simulate(std::chrono::milliseconds rtt, double rate, bool controlled = true,
                 CongestionControl::Options options = {}, bool announce = false) {
  CongestionControl cc(options);
  Path path{rtt / 2, rate};
  std::deque<TimePoint> pongs;  // due times; the path is FIFO, so they come back in order
  std::uint64_t position = 0, delivered = 0;
  bool pending = false;
  Outcome out;
  const TimePoint converged = t0 + kConverged, end = t0 + kLength;

  auto write = [&](TimePoint now, std::uint64_t bytes) {
    position += bytes;
    const TimePoint arrives = path.write(now, bytes);
    if (arrives >= converged && arrives < end) delivered += bytes;
    return arrives;
  };
  auto try_send = [&](TimePoint now) {
    if (!pending || (controlled && cc.is_congested(now))) return;
    pending = false;
    ++out.sent;
    write(now, kFrameBytes);
    cc.update_position(now, position);
    pongs.push_back(write(now, kPingBytes) + path.one_way);
    cc.sent_ping(now, position);
    if (now >= converged) out.worst_backlog = std::max(out.worst_backlog, path.backlog(now));
  };

  TimePoint next_frame = t0;
  if (announce) {
    // The server's first fence, before any frame: its round trip is the bare path's.
    pongs.push_back(write(t0, kPingBytes) + path.one_way);
    cc.sent_ping(t0, position);
    next_frame += rtt;
  }
  while (next_frame < end) {
    if (!pongs.empty() && pongs.front() <= next_frame) {
      const TimePoint now = pongs.front();
      pongs.pop_front();
      if (!cc.got_pong(now)) ++out.unasked_pongs;
      if (now >= converged) out.worst_rtt = std::max(out.worst_rtt, *cc.last_rtt());
      try_send(now);
      continue;
    }
    ++out.offered;
    pending = true;
    try_send(next_frame);
    next_frame += 33ms;
  }
  out.base_rtt = cc.base_rtt().value_or(microseconds{0});
  const std::chrono::duration<double> measured = kLength - kConverged;
  out.delivered_rate = static_cast<double>(delivered) / measured.count();
  out.estimated_rate = cc.delivery_rate();
  out.path_rate = cc.path_rate();
  return out;
}

}  // namespace

// Why these bounds hold: the ping after a frame also waits for the frame itself (64 ms at 5 Mbit/s), so
// baseRTT ~ 50 + 64 ms, and the queue the window leaves shows up as RTT above it. The window stops growing
// at 25 ms of queue and shrinks above 50 ms; the spike rule (100 ms) catches an overshoot. With 40 KB
// frames the queue moves in steps of one frame (64 ms): one or two frames queued, i.e. RTT <= baseRTT +
// ~80 ms, and it cannot grow over the minute. Once the window passes one frame plus the path's
// rate x RTT (~70 KB) a frame is always waiting at the bottleneck, so after the first seconds the link is
// nearly always busy: 80% leaves room for the window's sawtooth.
TEST_CASE("simulated 50 ms / 5 Mbit/s link: short queue, rate near the cap", "[congestion_control]") {
  constexpr double kCap = 5e6 / 8;  // bytes/s
  const Outcome out = simulate(50ms, kCap);
  INFO("sent " << out.sent << "/" << out.offered << ", base " << out.base_rtt.count() << " us, worst "
               << out.worst_rtt.count() << " us, backlog " << out.worst_backlog << " B, delivered "
               << out.delivered_rate << " B/s, estimate " << out.estimated_rate << " B/s");
  CHECK(out.unasked_pongs == 0);
  // Discounting each frame's own 64 ms on the link lets one more frame wait at the bottleneck than the
  // plain scheme does (below): up to one frame's time more on top of the plain bound.
  CHECK(out.worst_rtt < out.base_rtt + 100ms + 64ms);
  CHECK(out.worst_backlog < Path::kBufferBytes / 8);
  CHECK(out.delivered_rate >= 0.8 * kCap);
  // The estimate measures the bottleneck, not our offered 1.2 MB/s.
  CHECK(out.estimated_rate >= 0.8 * kCap);
  CHECK(out.estimated_rate <= 1.01 * kCap);
  // The path rate, learnt from each frame's time on the link, is the cap too.
  CHECK(out.path_rate >= 0.9 * kCap);
  CHECK(out.path_rate <= 1.1 * kCap);
  // Golden: the run is deterministic; a deliberate change to the window rules updates this and says why.
  CHECK(out.sent == 934);

  // The plain scheme: here every ping follows a frame, so its base RTT already holds one frame's time and
  // it too keeps the link full, with a queue of one or two frames at most.
  const Outcome plain = simulate(50ms, kCap, true, kPlainScheme);
  CHECK(plain.worst_rtt < plain.base_rtt + 100ms);
  CHECK(plain.delivered_rate >= 0.8 * kCap);

  // The control: the same sender ignoring the window fills the bottleneck's buffer for the whole minute.
  const Outcome uncontrolled = simulate(50ms, kCap, false);
  CHECK(uncontrolled.worst_rtt > 10s);
  CHECK(uncontrolled.worst_backlog > Path::kBufferBytes);
}

// The server announces Fence with a fence of its own before the first frame, so the lowest RTT it sees is
// the bare path's (50 ms), without any frame's time on the link. The plain scheme then reads each 40 KB
// frame's own 64 ms at 5 Mbit/s as a queue over its 50 ms limit and shrinks to one frame per round trip
// (~8.7 frames/s of the ~15.6 the link carries); discounting a frame's own time keeps the link full.
TEST_CASE("simulated 50 ms / 5 Mbit/s link after a bare fence: a frame's own time is not a queue",
          "[congestion_control]") {
  constexpr double kCap = 5e6 / 8;
  const Outcome out = simulate(50ms, kCap, true, {}, true);
  const Outcome plain = simulate(50ms, kCap, true, kPlainScheme, true);
  INFO("discounted: sent " << out.sent << ", " << out.delivered_rate << " B/s, worst " << out.worst_rtt.count()
                           << " us; plain: sent " << plain.sent << ", " << plain.delivered_rate << " B/s");
  CHECK(out.base_rtt < 51ms);  // the bare fence: 9 bytes cross 5 Mbit/s in 14 us
  CHECK(out.delivered_rate >= 0.8 * kCap);
  CHECK(out.worst_rtt < 50ms + 100ms + 2 * 64ms);
  CHECK(plain.delivered_rate < 0.7 * kCap);
}

// Why 90%: with no queue ever, slow start doubles each period (~RTT + 3 pings, ~0.27 s) from 16 KiB to
// the ~280 KB that 200 ms of 40 KB frames at 30/s need: 5 doublings, under 2 s of the 60, so ~97% of the
// frames go out; 90% leaves room. Every frame after that goes out at once.
TEST_CASE("simulated 200 ms link without a cap: the window opens for every frame", "[congestion_control]") {
  const Outcome out = simulate(200ms, 0);
  INFO("sent " << out.sent << "/" << out.offered);
  CHECK(out.unasked_pongs == 0);
  CHECK(out.sent >= 0.9 * out.offered);
  CHECK(out.worst_rtt == 200ms);
  // No queue ever formed, so nothing measured the link's capacity: the rate stays unknown.
  CHECK(out.estimated_rate == 0);
}
