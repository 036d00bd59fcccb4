// SPDX-License-Identifier: GPL-2.0-or-later
// CongestionControl: a delay-based window of bytes in flight to one client, driven by RTT pings alone.
//
// The server writes an RTT ping (a Fence with BlockBefore|Request) after each framebuffer update and the
// client answers fences in order, so each answer says "everything written before that ping has arrived".
// That is the only signal we use: the path may be a proxy that delays and caps the rate while our own
// socket never blocks. The window follows the published TigerVNC scheme (delay above the lowest RTT seen
// means a queue is building somewhere): slow start doubles it, queueing delay shrinks or holds it, and it
// only grows while it was actually what held the sender back. Knows nothing of sockets or RFB; time is
// passed in, so tests drive it with a fake clock.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

namespace rfbsim::detail {

/// Decides whether a client's link has room for another update. Not thread-safe: its client's
/// network thread owns it.
class CongestionControl {
 public:
  using Clock = std::chrono::steady_clock;
  using TimePoint = Clock::time_point;

  /// Window on a new connection and the most an idle one keeps, in bytes.
  static constexpr std::uint32_t kInitialWindow = 16 * 1024;
  /// The window never shrinks below this (bytes): one small update always fits.
  static constexpr std::uint32_t kMinWindow = 4 * 1024;
  /// The window never grows above this (bytes).
  static constexpr std::uint32_t kMaxWindow = 4 * 1024 * 1024;

  /// Choices that change the window's arithmetic.
  struct Options {
    /// Leave each update's own time on the path out of its RTT (and out of the base), using path_rate().
    /// On: a big update alone on a slow link reads as no queue, so the window can hold the link's
    /// rate x RTT plus an update and keep the link busy. Off: TigerVNC's plain scheme, where a base RTT
    /// learnt from a small fence makes every large update look queued (one update per round trip).
    bool discount_own_bytes = true;
  };

  CongestionControl() = default;
  explicit CongestionControl(const Options& options) : options_(options) {}

  /// The stream position (total bytes written to this client so far) at `now`; call after every write.
  void update_position(TimePoint now, std::uint64_t position);
  /// A ping was just written; the stream position is now `position` (it includes the ping).
  void sent_ping(TimePoint now, std::uint64_t position);
  /// The oldest outstanding ping was answered. false (and no change) when none is outstanding.
  bool got_pong(TimePoint now);

  /// True while the bytes in flight fill the window: start no new update now. Never true with nothing
  /// in flight.
  [[nodiscard]] bool is_congested(TimePoint now) const;
  /// Bytes written but not yet known to be received (written after the last answered ping).
  [[nodiscard]] std::uint64_t in_flight(TimePoint now) const;
  /// The congestion window in bytes, kMinWindow..kMaxWindow.
  [[nodiscard]] std::uint32_t window() const { return window_; }
  /// The lowest RTT seen since the connection (or its last idle restart) began; empty before a pong.
  [[nodiscard]] std::optional<std::chrono::microseconds> base_rtt() const { return base_rtt_; }
  /// The RTT of the latest answered ping; empty before a pong.
  [[nodiscard]] std::optional<std::chrono::microseconds> last_rtt() const { return last_rtt_; }
  /// Pings written and not yet answered.
  [[nodiscard]] std::size_t outstanding_pings() const { return pings_.size(); }
  /// Bytes per second the client received over the last few pongs while the window was the limit and
  /// a queue had formed (0 = unknown): the link's rate estimate, for quality/bitrate decisions.
  [[nodiscard]] double delivery_rate() const { return delivery_rate_; }
  /// Whether the window is still doubling each measurement period.
  [[nodiscard]] bool in_slow_start() const { return slow_start_; }
  /// The path's rate in bytes per second (0 = unknown), from how long each update took to arrive: the
  /// time from when its answer could first have come (a base RTT after it was written, or the previous
  /// answer if that came later) to when it came. The median of recent samples, so that one slow answer
  /// (a page busy decoding) does not drag it down. Unlike delivery_rate() it needs no queue: a stream that
  /// does not fill the link still learns what the link could carry.
  [[nodiscard]] double path_rate() const { return path_rate_; }

 private:
  struct Ping {
    TimePoint sent;
    std::uint64_t position;  // stream position just after the ping
    std::uint64_t burst;     // bytes written since the ping before it (the update it follows)
    bool window_limited;     // the window was full once it was written: the sender had to wait
  };
  struct RateAnchor {
    TimePoint at;
    std::uint64_t position;
  };

  void restart_after_idle(TimePoint now);
  void start_period(TimePoint now);
  void adjust_window(TimePoint now);
  void sample_rate(TimePoint now, const Ping& ping, std::chrono::microseconds rtt);
  void sample_path_rate(TimePoint now, const Ping& ping);
  std::chrono::microseconds queue_free_rtt(const Ping& ping, std::chrono::microseconds rtt) const;

  Options options_{};
  std::uint64_t position_ = 0;        // bytes written so far
  std::uint64_t acked_position_ = 0;  // position of the last answered ping
  std::deque<Ping> pings_;            // outstanding, oldest first
  TimePoint last_activity_{};         // last write or pong
  std::uint32_t window_ = kInitialWindow;
  bool slow_start_ = true;
  std::optional<std::chrono::microseconds> base_rtt_;
  std::optional<std::chrono::microseconds> last_rtt_;

  // The measurement period: pongs of pings written since the last window change.
  TimePoint period_start_{};
  int period_pongs_ = 0;
  std::chrono::microseconds period_min_rtt_{};
  bool period_limited_ = false;

  // Delivery rate: the last pong of an unbroken run of window-limited, queued pings, and the estimate.
  std::optional<RateAnchor> rate_anchor_;
  double delivery_rate_ = 0;

  // Path rate: the last answer's time, and recent per-update samples (bytes per second), newest last.
  std::optional<TimePoint> last_pong_at_;
  std::uint64_t last_ping_position_ = 0;
  std::deque<double> path_samples_;
  double path_rate_ = 0;
  // The lowest RTT seen less the update's own time on the path: the base the queue is measured from.
  std::optional<std::chrono::microseconds> free_base_;
};

}  // namespace rfbsim::detail
