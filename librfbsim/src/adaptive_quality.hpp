// SPDX-License-Identifier: GPL-2.0-or-later
// AdaptiveQuality: picks one client's JPEG quality from how often congestion control holds its frames.
//
// A frame held back by congestion control coalesces with the next one, so a link that cannot carry the
// frame rate at this quality shows as a share of held frames. Then the quality steps down one level of a
// ladder derived from the configured top quality, waits until the effect shows, and steps again if it
// must. Frames are also held when the client, not the link, is slow (a page decoding slowly, a busy
// laptop): its answers to our pings come late whatever the bytes. Smaller pictures do not help there, and
// that is how it shows: a step down that leaves frames held without sending more of them a second is taken
// back, and no step down is tried for a while. It steps back up once nothing has been held for a few seconds and the link's measured rate would
// carry the next level up; a step up that fails at once makes the next try wait twice as long. When the
// picture stops changing, a frame sent below the top level is refreshed once at the top level. Knows
// nothing of sockets or encoders; time is passed in, so tests drive it with a fake clock.
#pragma once

#include <chrono>
#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

namespace rfbsim::detail {

/// One rung of the quality ladder.
struct QualityLevel {
  int jpeg_quality;  ///< 1..100
  int subsampling;   ///< libvncserver's index: 0 = 4:4:4, 1 = 4:2:0, 2 = 4:2:2
  bool operator==(const QualityLevel&) const = default;
};

/// Tuning of AdaptiveQuality; the defaults suit a 30 fps stream.
struct AdaptiveQualityConfig {
  int top_quality = 80;    ///< JPEG quality of the best level (clamped to 1..100)
  int floor_quality = 20;  ///< the lowest level's JPEG quality (the top one if that is lower)
  std::chrono::milliseconds window{1000};     ///< how far back held frames are counted
  double held_share_down = 0.25;              ///< share of held frames in `window` that steps down
  std::size_t min_frames = 5;                 ///< fewer frames than this in `window` decide nothing
  std::chrono::milliseconds hold_off{1500};   ///< no change this soon after the last one
  std::chrono::milliseconds recovery{3000};   ///< time without a held frame before stepping up
  double up_headroom = 1.25;                  ///< the rate must carry the next level this many times over
  std::chrono::milliseconds probe_after{30000};  ///< step up against the rate after this long unheld
  std::chrono::milliseconds probation{10000};    ///< a step down this soon after a step up: it failed
  int max_backoff = 8;  ///< failed step ups multiply `recovery` and `probe_after` by up to this
  std::chrono::milliseconds still_delay{500};  ///< a picture still this long is refreshed at the top level
  double useful_gain = 1.15;  ///< a step down that still holds frames must raise the sent frame rate this much
  std::chrono::milliseconds slow_client_wait{30000};  ///< no step down this long after one was taken back
};

/// The ladder for `top_quality`: about 1, 0.8, 0.6 and 0.45 of it, then `floor_quality`, all 4:2:0,
/// strictly decreasing; a single level when the top is at or below the floor.
std::vector<QualityLevel> quality_ladder(int top_quality, int floor_quality);

/// Expected bytes of a JPEG at quality `to` over one at quality `from`, same picture and subsampling.
double jpeg_size_ratio(int from, int to);

/// Picks the JPEG quality for one client. Not thread-safe: its client's network thread owns it.
class AdaptiveQuality {
 public:
  using Clock = std::chrono::steady_clock;
  using TimePoint = Clock::time_point;

  /// Starts at the top level.
  explicit AdaptiveQuality(const AdaptiveQualityConfig& config = {});

  /// A new frame was ready for this client at `now`; `held`: congestion control held it back (it will
  /// coalesce). Holds while the window is still in slow start measure the window, not the link: pass
  /// false for those.
  void frame_offered(TimePoint now, bool held);
  /// A frame encoded at current() went out at `now`, `bytes` long (not the still refresh: see below).
  void frame_sent(TimePoint now, std::size_t bytes);
  /// Applies the step rules at `now`; `delivery_rate` is the link's rate in bytes/s (0 = unknown).
  /// Returns true when the level changed. Call once per offered frame, after frame_offered().
  bool adjust(TimePoint now, double delivery_rate);

  /// The picture changed at `now` (damage to be sent).
  void scene_changed(TimePoint now);
  /// True once the picture has been still for `still_delay` and the last frame went out below the top.
  [[nodiscard]] bool wants_still_refresh(TimePoint now) const;
  /// The still picture was just sent again at levels().front(); call instead of frame_sent().
  void still_refreshed();

  /// Index of the current level in levels(); 0 is the top.
  [[nodiscard]] std::size_t level() const { return level_; }
  /// The level to encode the next frame at.
  [[nodiscard]] const QualityLevel& current() const { return levels_[level_]; }
  /// The whole ladder, best first.
  [[nodiscard]] const std::vector<QualityLevel>& levels() const { return levels_; }
  /// Bytes per frame expected one level up (0 at the top or before three frames at this level).
  [[nodiscard]] double next_level_bytes() const;
  /// True once the quality is below the top and the step there has shown that it helped (more frames sent a
  /// second, or none held): the link, not the client, limits the stream.
  [[nodiscard]] bool link_bound() const { return level_ > 0 && step_down_helped_; }
  /// True while step downs wait because the last one did not help (the client, not the link, is slow).
  [[nodiscard]] bool client_bound(TimePoint now) const { return no_step_down_until_ && now < *no_step_down_until_; }

 private:
  struct Offer {
    TimePoint at;
    bool held;
  };

  struct StepDown {
    TimePoint at;
    std::size_t from;   // the level it left
    double sent_fps;    // frames sent a second at that level, just before
  };

  void forget_old_frames(TimePoint now);
  void change_level(TimePoint now, std::size_t level);
  [[nodiscard]] double sent_fps() const;
  // After a step down's hold-off: keeps it when it helped, takes it back when frames are still held and it did
  // not raise the sent frame rate. Returns true when it took it back.
  bool judge_step_down(TimePoint now, bool too_many_held);

  AdaptiveQualityConfig config_;
  std::vector<QualityLevel> levels_;
  std::size_t level_ = 0;

  std::deque<Offer> offers_;              // the last `window` of offered frames
  std::optional<TimePoint> last_change_;  // or the first offer, before any change
  std::optional<TimePoint> last_held_;
  double bytes_per_frame_ = 0;            // smoothed, at this level
  std::size_t sent_at_level_ = 0;
  std::optional<TimePoint> last_step_up_;  // still on probation
  int backoff_ = 1;                        // doubles per failed step up

  std::deque<TimePoint> sent_;              // frames sent in the last `window`
  std::optional<StepDown> last_step_down_;  // not yet judged
  bool step_down_helped_ = false;           // a step down since the top was judged and kept
  std::optional<TimePoint> no_step_down_until_;
  int slow_client_backoff_ = 1;             // doubles per step down taken back

  std::optional<TimePoint> last_damage_;
  bool low_frame_on_screen_ = false;  // the last frame went out below the top and was not refreshed
};

}  // namespace rfbsim::detail
