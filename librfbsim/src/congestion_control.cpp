// SPDX-License-Identifier: GPL-2.0-or-later
// CongestionControl: window arithmetic of the delay-based scheme (thresholds as published by TigerVNC).
#include "congestion_control.hpp"

#include <algorithm>
#include <cassert>

namespace rfbsim::detail {

namespace {

using std::chrono::microseconds;
using namespace std::chrono_literals;

constexpr int kPongsPerPeriod = 3;            // measurements before the window may change
constexpr auto kSlowStartQueue = 25ms;        // this much queueing delay ends slow start
constexpr auto kSpikeQueue = 100ms;           // ... and this much (if also > baseRTT / 2) is a spike
constexpr auto kEmptyQueue = 5ms;             // below this the path is idle: grow fast
constexpr auto kShortQueue = 25ms;            // below this grow slowly; 25..50 ms hold
constexpr auto kLongQueue = 50ms;             // above this shrink
constexpr std::uint32_t kFastStep = 8 * 1024;
constexpr std::uint32_t kSlowStep = 4 * 1024;
constexpr auto kIdleMin = 100ms;              // idle longer than this and 2 x baseRTT restarts
constexpr auto kRateSpan = 100ms;             // one delivery-rate sample spans at least this
constexpr double kRateGain = 0.25;            // weight of a new sample in the smoothed rate
constexpr std::uint64_t kMinPathBurst = 2048;  // smaller updates arrive too fast to time
constexpr auto kMinPathSpread = 200us;        // ... and so do answers closer together than this
constexpr std::size_t kPathSamples = 9;       // the path rate is the median of this many samples

std::uint32_t clamp_window(std::int64_t bytes) {
  return static_cast<std::uint32_t>(std::clamp<std::int64_t>(bytes, CongestionControl::kMinWindow,
                                                             CongestionControl::kMaxWindow));
}

// The window that would have kept the queue empty: the same rate at the lower RTT.
std::uint32_t scale(std::uint32_t window, microseconds base, microseconds measured) {
  return clamp_window(static_cast<std::int64_t>(window) * base.count() / measured.count());
}

}  // namespace

void CongestionControl::update_position(TimePoint now, std::uint64_t position) {
  assert(position >= position_ && "CongestionControl: the stream position went back");
  if (position == position_) return;
  // Writing again after a silence: what the window learnt may no longer hold (other traffic, a new
  // route), and a full old window sent at once would be a burst the path never saw from us.
  const auto idle_limit = std::max<Clock::duration>(kIdleMin, 2 * base_rtt_.value_or(0us));
  if (position_ == acked_position_ && now - last_activity_ > idle_limit) restart_after_idle(now);
  position_ = position;
  last_activity_ = now;
}

void CongestionControl::sent_ping(TimePoint now, std::uint64_t position) {
  update_position(now, position);
  // A ping that leaves the window full means the next update has to wait: the window is the limit,
  // and only then does the answer say anything about whether the window could be larger.
  pings_.push_back({now, position, position - last_ping_position_, in_flight(now) >= window_});
  last_ping_position_ = position;
}

bool CongestionControl::got_pong(TimePoint now) {
  if (pings_.empty()) return false;
  const Ping ping = pings_.front();
  pings_.pop_front();
  acked_position_ = ping.position;
  last_activity_ = now;

  // The RTT; base RTT is the path without our queue (clamped so a same-instant answer cannot divide
  // by zero).
  const auto rtt = std::max(microseconds{1}, std::chrono::duration_cast<microseconds>(now - ping.sent));
  last_rtt_ = rtt;
  if (!base_rtt_ || rtt < *base_rtt_) base_rtt_ = rtt;
  sample_rate(now, ping, rtt);
  sample_path_rate(now, ping);

  // Both the base and each measurement leave out the update's own time on the path, so that a big
  // update on a slow link, alone on it, reads as no queue (see queue_free_rtt).
  const microseconds measured = queue_free_rtt(ping, rtt);
  if (!free_base_ || measured < *free_base_) free_base_ = measured;

  // Pings written before the last change measured the old window: they do not count towards the next.
  if (ping.sent < period_start_) return true;
  period_min_rtt_ = period_pongs_ == 0 ? measured : std::min(period_min_rtt_, measured);
  period_limited_ = period_limited_ || ping.window_limited;
  if (++period_pongs_ >= kPongsPerPeriod) adjust_window(now);
  return true;
}

bool CongestionControl::is_congested(TimePoint now) const { return in_flight(now) >= window_; }

// In flight = written after the last answered ping, as TCP counts unacknowledged bytes. Interpolating
// between pongs (guessing how much the client has received since) needs the one-way delay and the rate,
// which we cannot see; the plain count is exact, and the window is calibrated against this same count
// (it settles at about rate x RTT), so the guess would buy nothing. `now` is not needed for it.
std::uint64_t CongestionControl::in_flight(TimePoint /*now*/) const { return position_ - acked_position_; }

void CongestionControl::restart_after_idle(TimePoint now) {
  window_ = std::min(window_, kInitialWindow);
  slow_start_ = true;
  // The lowest RTT is learnt again too: a path that got longer while idle would otherwise read as a
  // standing queue and shrink the window for good.
  base_rtt_.reset();
  free_base_.reset();
  rate_anchor_.reset();
  start_period(now);
}

void CongestionControl::start_period(TimePoint now) {
  period_start_ = now;
  period_pongs_ = 0;
  period_limited_ = false;
}

void CongestionControl::adjust_window(TimePoint now) {
  const microseconds base = free_base_.value_or(*base_rtt_);
  const microseconds measured = period_min_rtt_;  // the least-queued ping of the period
  const microseconds queue = measured - base;

  if (queue > kSpikeQueue && queue > base / 2) {
    // A spike: far more delay than slow growth could have caused; fall back to the queue-free window.
    window_ = scale(window_, base, measured);
    slow_start_ = false;
  } else if (slow_start_) {
    // Double until a queue shows, then drop to the window that had no queue and grow slowly.
    if (queue >= kSlowStartQueue) {
      window_ = scale(window_, base, measured);
      slow_start_ = false;
    } else if (period_limited_) {
      window_ = clamp_window(std::int64_t{window_} * 2);
    }
  } else if (queue > kLongQueue) {
    // Shrinking needs no window-limited period: any queue this long is worth draining.
    window_ = clamp_window(std::int64_t{window_} - kSlowStep);
  } else if (period_limited_ && queue < kEmptyQueue) {
    window_ = clamp_window(std::int64_t{window_} + kFastStep);
  } else if (period_limited_ && queue < kShortQueue) {
    window_ = clamp_window(std::int64_t{window_} + kSlowStep);
  }
  start_period(now);
}

// A sample is taken only between pongs of pings that (a) found the window full and (b) waited in a
// queue: then the bottleneck was busy the whole time, so the pongs come back spaced by its rate. Without
// a queue the pongs only echo our own sending rate (in slow start: window / RTT), which says nothing
// about what the link could carry.
void CongestionControl::sample_rate(TimePoint now, const Ping& ping, microseconds rtt) {
  const bool bottleneck_busy = ping.window_limited && rtt - *base_rtt_ >= kEmptyQueue;
  if (!bottleneck_busy) {
    rate_anchor_.reset();
    return;
  }
  if (!rate_anchor_) {
    rate_anchor_ = RateAnchor{now, ping.position};
    return;
  }
  // Pongs of small updates can arrive nearly together; a span of a few of them is a steadier sample.
  const auto span = now - rate_anchor_->at;
  if (span < kRateSpan) return;
  const double sample = static_cast<double>(ping.position - rate_anchor_->position) /
                        std::chrono::duration<double>(span).count();
  delivery_rate_ = delivery_rate_ == 0 ? sample : delivery_rate_ + kRateGain * (sample - delivery_rate_);
  rate_anchor_ = RateAnchor{now, ping.position};
}

// An update's answer comes at the earliest a base RTT after it was written, and not before the previous
// answer (its bytes queue behind the earlier ones). The time past that is how long its own bytes took to
// cross the slowest hop (or the client to take them in): bytes / that time is a sample of the path's rate,
// queue or no queue.
void CongestionControl::sample_path_rate(TimePoint now, const Ping& ping) {
  const std::optional<TimePoint> previous = last_pong_at_;
  last_pong_at_ = now;
  if (!base_rtt_ || ping.burst < kMinPathBurst) return;
  TimePoint earliest = ping.sent + free_base_.value_or(*base_rtt_);
  if (previous && *previous > earliest) earliest = *previous;
  const auto spread = now - earliest;
  if (spread < kMinPathSpread) return;
  path_samples_.push_back(static_cast<double>(ping.burst) / std::chrono::duration<double>(spread).count());
  if (path_samples_.size() > kPathSamples) path_samples_.pop_front();
  std::vector<double> sorted(path_samples_.begin(), path_samples_.end());
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  path_rate_ = sorted[sorted.size() / 2];
}

// The RTT without the time the update's own bytes needed to cross the path: a big update on a slow link
// takes long to arrive even with nothing ahead of it, and that is not a queue. What remains above the base
// (measured the same way) is waiting behind earlier bytes, which is what the window must keep short.
// Without this, a base RTT learnt from a small fence makes every large update look queued, and the window
// falls to one update per round trip. Without a path rate yet, the RTT as measured.
microseconds CongestionControl::queue_free_rtt(const Ping& ping, microseconds rtt) const {
  if (!options_.discount_own_bytes || path_rate_ <= 0 || !base_rtt_) return rtt;
  const auto own = std::chrono::duration_cast<microseconds>(
      std::chrono::duration<double>(static_cast<double>(ping.burst) / path_rate_));
  // Never below the lowest RTT actually seen: a rate underestimated (a page slow to take pictures in)
  // would otherwise push the base below the path's and make every later answer look queued.
  return std::max(*base_rtt_, rtt - own);
}

}  // namespace rfbsim::detail
