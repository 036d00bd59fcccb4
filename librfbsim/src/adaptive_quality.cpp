// SPDX-License-Identifier: GPL-2.0-or-later
// AdaptiveQuality: the quality ladder, the JPEG size model and the step rules.
#include "adaptive_quality.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace rfbsim::detail {

namespace {

constexpr int k420 = 1;                // libvncserver's 4:2:0 index
constexpr std::size_t kMinSamples = 3;  // frames at a level before its bytes per frame count
constexpr double kBytesGain = 1.0 / 8;  // weight of one frame in the smoothed bytes per frame

// libjpeg's quality scaling: the quantisation tables are scaled by this percentage (never below 1).
double ijg_scale(int quality) {
  const int q = std::clamp(quality, 1, 100);
  return std::max(1.0, q < 50 ? 5000.0 / q : 200.0 - 2.0 * q);
}

}  // namespace

// About 1, 0.8, 0.6, 0.45 of the top: by jpeg_size_ratio each step saves roughly 1.3..1.5x the bytes,
// enough that one or two steps relieve a link, little enough that no step throws away more picture
// than needed. 4:2:0 throughout: the eye misses chroma detail least, so it is given up at every level.
std::vector<QualityLevel> quality_ladder(int top_quality, int floor_quality) {
  const int top = std::clamp(top_quality, 1, 100);
  const int floor = std::clamp(floor_quality, 1, top);
  std::vector<QualityLevel> ladder{{top, k420}};
  for (const double share : {0.8, 0.6, 0.45}) {
    const int q = static_cast<int>(std::lround(top * share));
    if (q > floor && q < ladder.back().jpeg_quality) ladder.push_back({q, k420});
  }
  if (floor < top) ladder.push_back({floor, k420});
  return ladder;
}

// Size model: bytes ~ scale^-0.6, i.e. halving every quantisation step costs about 1.5x the bytes, a
// rough fit to commonly quoted JPEG sizes between quality 25 and 90 (text-heavy or flat pictures grow
// less). It only sizes a step up; erring large there makes a step up wait for more rate, the safe side.
double jpeg_size_ratio(int from, int to) { return std::pow(ijg_scale(from) / ijg_scale(to), 0.6); }

AdaptiveQuality::AdaptiveQuality(const AdaptiveQualityConfig& config)
    : config_(config), levels_(quality_ladder(config.top_quality, config.floor_quality)) {}

void AdaptiveQuality::frame_offered(TimePoint now, bool held) {
  if (!last_change_) last_change_ = now;  // the first hold-off runs from the first frame
  offers_.push_back({now, held});
  if (held) last_held_ = now;
  forget_old_frames(now);
}

void AdaptiveQuality::frame_sent(TimePoint now, std::size_t bytes) {
  sent_.push_back(now);
  forget_old_frames(now);
  const auto b = static_cast<double>(bytes);
  bytes_per_frame_ = sent_at_level_ == 0 ? b : bytes_per_frame_ + kBytesGain * (b - bytes_per_frame_);
  ++sent_at_level_;
  low_frame_on_screen_ = level_ > 0;
}

bool AdaptiveQuality::adjust(TimePoint now, double delivery_rate) {
  if (!last_change_) return false;  // nothing offered yet
  forget_old_frames(now);

  // A step up that lasted its probation was right: the next failure starts from the short wait again.
  if (last_step_up_ && now - *last_step_up_ >= config_.probation) {
    last_step_up_.reset();
    backoff_ = 1;
  }
  // Let the last change show (congestion control drains what the old level queued) before judging.
  if (now - *last_change_ < config_.hold_off) return false;

  // Down: the link did not carry the frame rate at this level. Only frames offered after the change.
  std::size_t offered = 0;
  std::size_t held = 0;
  for (const Offer& offer : offers_) {
    if (offer.at <= *last_change_) continue;
    ++offered;
    held += offer.held ? 1 : 0;
  }
  const bool too_many_held = offered >= config_.min_frames &&
                             static_cast<double>(held) >= config_.held_share_down * static_cast<double>(offered);
  if (judge_step_down(now, too_many_held)) return true;
  if (level_ + 1 < levels_.size() && too_many_held && !client_bound(now)) {
    // Having to step down right after a step up means that step up was wrong: wait longer next time.
    if (last_step_up_) backoff_ = std::min(backoff_ * 2, config_.max_backoff);
    last_step_up_.reset();
    const StepDown step{now, level_, sent_fps()};
    change_level(now, level_ + 1);
    last_step_down_ = step;
    return true;
  }

  // Up: nothing held for a while. The rate must carry the next level's frames with headroom (the gap
  // between this and the down rule is the hysteresis); 0 = no queue ever measured, nothing says no.
  // A rate that says no may be stale (measured when the link was busier), so after a long calm the
  // step is tried anyway; if it fails at once, backoff_ spaces the tries out.
  if (level_ == 0 || sent_at_level_ < kMinSamples) return false;
  const TimePoint calm_since = std::max(*last_change_, last_held_.value_or(*last_change_));
  const double frame_rate =
      static_cast<double>(offers_.size()) / std::chrono::duration<double>(config_.window).count();
  const double needed = config_.up_headroom * frame_rate * next_level_bytes();
  const bool rate_allows = delivery_rate <= 0 || delivery_rate >= needed;
  const auto wait = (rate_allows ? config_.recovery : config_.probe_after) * backoff_;
  if (now - calm_since < wait) return false;
  change_level(now, level_ - 1);
  last_step_up_ = now;
  return true;
}

// On a slow link, smaller pictures go through faster: a step down sends more frames a second (about 1.3 to
// 1.5 times as many, by jpeg_size_ratio), or none are held any more. A client that is slow per picture
// (decoding, a busy CPU) takes pictures at its own pace whatever their size, so there the step only costs
// picture quality: take it back, and do not try again for slow_client_wait (doubling each time it happens
// again, as conditions may change).
bool AdaptiveQuality::judge_step_down(TimePoint now, bool too_many_held) {
  if (!last_step_down_) return false;
  const StepDown step = *std::exchange(last_step_down_, std::nullopt);
  if (!too_many_held || sent_fps() >= config_.useful_gain * step.sent_fps) {
    step_down_helped_ = true;
    slow_client_backoff_ = 1;  // the link is the limit now: a slow client later is a new finding
    return false;
  }
  change_level(now, step.from);
  no_step_down_until_ = now + config_.slow_client_wait * slow_client_backoff_;
  slow_client_backoff_ = std::min(slow_client_backoff_ * 2, config_.max_backoff);
  return true;
}

double AdaptiveQuality::sent_fps() const {
  return static_cast<double>(sent_.size()) / std::chrono::duration<double>(config_.window).count();
}

void AdaptiveQuality::scene_changed(TimePoint now) { last_damage_ = now; }

bool AdaptiveQuality::wants_still_refresh(TimePoint now) const {
  if (!low_frame_on_screen_) return false;
  return !last_damage_ || now - *last_damage_ >= config_.still_delay;
}

void AdaptiveQuality::still_refreshed() { low_frame_on_screen_ = false; }

double AdaptiveQuality::next_level_bytes() const {
  if (level_ == 0 || sent_at_level_ < kMinSamples) return 0;
  return bytes_per_frame_ * jpeg_size_ratio(levels_[level_].jpeg_quality, levels_[level_ - 1].jpeg_quality);
}

void AdaptiveQuality::forget_old_frames(TimePoint now) {
  while (!offers_.empty() && offers_.front().at <= now - config_.window) offers_.pop_front();
  while (!sent_.empty() && sent_.front() <= now - config_.window) sent_.pop_front();
}

void AdaptiveQuality::change_level(TimePoint now, std::size_t level) {
  level_ = level;
  if (level_ == 0) step_down_helped_ = false;
  last_change_ = now;
  // Bytes per frame are measured afresh: the old level's say nothing exact about the new one.
  bytes_per_frame_ = 0;
  sent_at_level_ = 0;
}

}  // namespace rfbsim::detail
