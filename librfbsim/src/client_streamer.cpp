// SPDX-License-Identifier: GPL-2.0-or-later
// ClientStreamer: when, how and at which quality one client's updates go out.
#include "client_streamer.hpp"

#include <rfb/rfb.h>
// rfbregion.h lacks the extern "C" that rfb.h has.
extern "C" {
#include <rfb/rfbregion.h>
}

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "h264_encoder.hpp"
#include "rfbsim/log.hpp"

namespace rfbsim::detail {

namespace {

// Our pings carry one byte, well inside what every client echoes correctly (noVNC breaks above 64).
constexpr std::uint8_t kPingPayload[] = {'p'};
// Bytes of a fence with that payload: type, 3 padding, U32 flags, U8 length, payload.
constexpr std::uint64_t kPingBytes = 9 + sizeof kPingPayload;
// H.264's rate cap from the link's measured rate: leave room for the fences, input echo and jitter.
constexpr double kH264ShareOfLink = 0.8;
// The lowest cap, in bits per pixel of each picture: 0.06 is 1.7 Mbit/s at 1280x720 and 30 frames a second,
// about where the warehouse walk at 720p still looks sharp enough to read the HUD; below it fewer pictures
// (the congestion window) are the better trade than blurrier ones.
constexpr double kH264MinCapBitsPerPixel = 0.06;
// How long after the last held picture the H.264 stream stays capped at the link's rate.
constexpr auto kH264CapHold = std::chrono::seconds(5);

// libvncserver's regions are guarded by updateMutex (its FBUR handler takes it too).
class UpdateLock {
 public:
  explicit UpdateLock(rfbClientPtr client) : client_(client) {
#ifdef LIBVNCSERVER_HAVE_LIBPTHREAD
    pthread_mutex_lock(&client_->updateMutex);
#endif
  }
  ~UpdateLock() {
#ifdef LIBVNCSERVER_HAVE_LIBPTHREAD
    pthread_mutex_unlock(&client_->updateMutex);
#endif
  }
  UpdateLock(const UpdateLock&) = delete;
  UpdateLock& operator=(const UpdateLock&) = delete;

 private:
  rfbClientPtr client_;
};

void add_rect(sraRegionPtr region, const PixelRect& r) {
  sraRegionPtr rect = sraRgnCreateRect(r.x, r.y, r.x + r.w, r.y + r.h);
  sraRgnOr(region, rect);
  sraRgnDestroy(rect);
}

// Whether the picture itself has changes to send. libvncserver's FB_UPDATE_PENDING also counts cursor and
// desktop-size news, which only its own updates deliver (and clear): an H.264 stream, which never sends
// them, would otherwise look due on every pass.
bool picture_changed(rfbClientPtr client) {
  return !sraRgnEmpty(client->modifiedRegion) || !sraRgnEmpty(client->copyRegion);
}

AdaptiveQualityConfig quality_config(const StreamerConfig& config) {
  AdaptiveQualityConfig c;
  c.top_quality = config.jpeg_quality > 0 ? config.jpeg_quality : 80;
  return c;
}

}  // namespace

ClientStreamer::ClientStreamer(const StreamerConfig& config) : config_(config), quality_(quality_config(config)) {}

ClientStreamer::~ClientStreamer() = default;

bool ClientStreamer::fence_answered(TimePoint now) { return congestion_.got_pong(now); }

void ClientStreamer::after_messages(rfbClientPtr client) {
  if (!protocol_.offers_fence || client->sock == RFB_INVALID_SOCKET) return;
  const auto now = Clock::now();
  // TigerVNC's order, which noVNC expects: a ServerFence (with Request: noVNC fails on one without) so
  // the client knows we do fences, then one EndOfContinuousUpdates to say we do those too. The fence's
  // answer is the first round-trip sample.
  if (!protocol_.fence_announced) {
    if (!write_fence(client, kFenceRequest, kPingPayload)) return;
    protocol_.fence_announced = true;
    protocol_.position += kPingBytes;
    congestion_.sent_ping(now, protocol_.position);
  }
  if (protocol_.offers_continuous && !protocol_.announced) {
    if (!write_end_of_continuous_updates(client)) return;
    protocol_.announced = true;
    protocol_.position += 1;
    congestion_.update_position(now, protocol_.position);
  }
}

void ClientStreamer::frame_changed(TimePoint now) {
  new_frame_ = true;
  quality_.scene_changed(now);
}

ClientStreamer::Sent ClientStreamer::serve(rfbClientPtr client, TimePoint now, const std::uint8_t* framebuffer) {
  Sent sent;
  const bool fresh = std::exchange(new_frame_, false);
  const bool pushed = protocol_.continuous;
  if (pushed && config_.adaptive_quality && !h264_ && quality_.wants_still_refresh(now)) {
    // The picture stood still after frames went out below the top quality: send it again, whole, at top.
    UpdateLock lock(client);
    add_rect(client->modifiedRegion, {0, 0, config_.width, config_.height});
    still_refresh_ = true;
  }
  const bool h264 = use_h264();
  if (!(h264 ? picture_changed(client) : FB_UPDATE_PENDING(client))) return sent;
  if (pushed) {
    UpdateLock lock(client);
    if (congestion_.is_congested(now)) {
      // Held: the change stays in modifiedRegion and merges with later ones (latest pixels win). An
      // incremental request must not slip an update past the window, so the requested area is dropped.
      if (fresh) {
        ++updates_held_;
        // Holds while the window is still opening say nothing about the link.
        if (!congestion_.in_slow_start()) last_hold_ = now;
        offer_frame(now, true);
      }
      sraRgnMakeEmpty(client->requestedRegion);
      return sent;
    }
    if (fresh) offer_frame(now, false);
    // libvncserver only sends what was requested and forgets the request after each update.
    add_rect(client->requestedRegion, protocol_.continuous_area);
  } else if (sraRgnEmpty(client->requestedRegion)) {
    return sent;  // a requesting client that has not asked yet
  }

  if (h264) {
    sent = send_h264(client, now, framebuffer);
  } else {
    sent.update = rfbUpdateClient(client) != FALSE;
  }
  if (!sent.update || client->sock == RFB_INVALID_SOCKET) return sent;
  count_update(now);
  // Every update to a fence client is followed by a ping, requested ones too: the window counts bytes
  // since the last answered ping, so an update without one would stay in flight for good.
  if (protocol_.fence_announced) ping(client, now);
  if (still_refresh_) {
    still_refresh_ = false;
    quality_.still_refreshed();
  }
  return sent;
}

std::optional<QualityLevel> ClientStreamer::tight_quality() const {
  if (config_.jpeg_quality <= 0) return std::nullopt;
  // The top level keeps the configured subsampling, lowered to what the client asked for; the ladder below it
  // is 4:2:0 (or the client's coarser choice) and already starts at the client's quality (client_requested()).
  const QualityLevel top = client_top();
  // Only pushed streams have the fences that tell a slow link apart from a slow client.
  if (!config_.adaptive_quality || !protocol_.continuous || still_refresh_ || quality_.level() == 0) return top;
  return capped_by_client(quality_.current(), request_);
}

QualityLevel ClientStreamer::client_top() const {
  return capped_by_client({config_.jpeg_quality, config_.subsampling}, request_);
}

AdaptiveQualityConfig ClientStreamer::client_ladder_config() const {
  AdaptiveQualityConfig c = quality_config(config_);
  c.top_quality = client_top().jpeg_quality;
  return c;
}

void ClientStreamer::client_requested(const ClientQualityRequest& request) {
  if (request == request_) return;
  request_ = request;
  if (config_.jpeg_quality <= 0) return;
  // The client's quality is the top of its ladder: the ladder is rebuilt (and starts at its top) when that
  // top moves, as at a client's first SetEncodings or when TigerVNC's AutoSelect picks another level.
  if (client_top().jpeg_quality == quality_.levels().front().jpeg_quality) return;
  quality_ = AdaptiveQuality(client_ladder_config());
}

void ClientStreamer::offer_frame(TimePoint now, bool held) {
  // H.264's bitrate follows the link by its own cap (send_h264): the JPEG ladder has nothing to say there.
  if (!config_.adaptive_quality || h264_) return;
  // While the window is still in slow start, a held frame says the window is small, not the link slow.
  quality_.frame_offered(now, held && !congestion_.in_slow_start());
  quality_.adjust(now, congestion_.path_rate());
}

void ClientStreamer::tight_update_written(TimePoint now, std::uint64_t bytes) {
  protocol_.position += bytes;
  congestion_.update_position(now, protocol_.position);
  // The still refresh is one big top-quality picture: it would skew the level's bytes per frame.
  if (!still_refresh_) quality_.frame_sent(now, bytes);
}

bool ClientStreamer::use_h264() {
  if (h264_) return true;
  if (h264_failed_ || !protocol_.offers_h264) return false;
  switch (config_.codec) {
    case Codec::kJpeg: return false;
    case Codec::kH264: break;
    // Switch once the link could not carry the top JPEG quality: a step down that helped, since a client that
    // is slow per picture gains nothing from fewer bytes (and decoding H.264 may be slower still: Firefox);
    // stay, since H.264 is what made it fit.
    case Codec::kAuto:
      if (!quality_.link_bound()) return false;
      break;
  }
  try {
    encoder_ = std::make_unique<H264Encoder>(config_.width, config_.height, config_.frame_rate);
  } catch (const std::exception& e) {
    rfbsim::log::info("rfbsim.server", "H.264 unavailable, staying with Tight JPEG: %s", e.what());
    h264_failed_ = true;
    return false;
  }
  h264_ = true;
  // The ladder applies to Tight only; should H.264 fail later, Tight starts again from the (client's) top.
  quality_ = AdaptiveQuality(client_ladder_config());
  return true;
}

ClientStreamer::Sent ClientStreamer::send_h264(rfbClientPtr client, TimePoint now, const std::uint8_t* framebuffer) {
  Sent sent;
  const bool first = encoder_->frames_encoded() == 0;
  // A new decoder (first picture) or a full request (the client lost its picture) needs an IDR.
  const bool asked = std::exchange(protocol_.full_update_requested, false);
  const bool idr = first || asked;
  // Capped only while the link is what holds pictures back, at the rate the client then received (the
  // link's, since it was full). A cap drawn from a stream that fits the link easily would measure only
  // our own pace, and each picture made smaller by it would lower the next cap: it would only ever fall.
  const double rate = congestion_.delivery_rate();
  const bool link_bound = last_hold_ && now - *last_hold_ < kH264CapHold;
  // A floor too: when the page, not the link, is what holds pictures back (a browser decoding slowly), the
  // rate it takes in follows our own bitrate down, and smaller pictures would not help it.
  const double cap = std::max(rate * 8.0 * kH264ShareOfLink, kH264MinCapBitsPerPixel * config_.width *
                                                                  config_.height * config_.frame_rate);
  encoder_->set_max_bitrate(link_bound && rate > 0 ? static_cast<int>(std::min(cap, 2e9)) : 0);
  const auto started = Clock::now();
  std::vector<std::uint8_t> picture;
  try {
    picture = encoder_->encode(framebuffer, config_.width * 4, idr);
  } catch (const std::exception& e) {
    // The encoder is unusable after a failure: this client goes back to Tight (whose first update is
    // whole: everything is marked changed), with a context reset so the page drops its H.264 decoder.
    rfbsim::log::warn("rfbsim.server", "H.264 encoding failed, back to Tight JPEG: %s", e.what());
    encoder_.reset();
    h264_ = false;
    h264_failed_ = true;
    UpdateLock lock(client);
    add_rect(client->modifiedRegion, {0, 0, config_.width, config_.height});
    return sent;
  }
  // Whatever the client's decoder held before this stream (Tight pictures, another context) is reset.
  std::vector<std::uint8_t> message = h264_update_header(config_.width, config_.height,
                                                         static_cast<std::uint32_t>(picture.size()),
                                                         first ? kH264ResetAllContexts : 0U);
  message.insert(message.end(), picture.begin(), picture.end());
  {
    UpdateLock lock(client);
    sraRgnMakeEmpty(client->modifiedRegion);
    sraRgnMakeEmpty(client->copyRegion);
    sraRgnMakeEmpty(client->requestedRegion);
  }
  if (!write_message(client, message)) return sent;
  sent.update = true;
  sent.bytes = message.size();
  sent.encode = Clock::now() - started;
  protocol_.position += message.size();
  congestion_.update_position(now, protocol_.position);
  return sent;
}

void ClientStreamer::ping(rfbClientPtr client, TimePoint now) {
  // BlockBefore: the client answers only after handling the update before it, so the round trip covers
  // the update's delivery and decoding.
  if (!write_fence(client, kFenceBlockBefore | kFenceRequest, kPingPayload)) return;
  protocol_.position += kPingBytes;
  congestion_.sent_ping(now, protocol_.position);
}

void ClientStreamer::count_update(TimePoint now) {
  ++updates_sent_;
  ++rate_window_updates_;
  const auto span = now - rate_window_start_;
  if (span >= std::chrono::seconds(1)) {
    fps_ = static_cast<double>(rate_window_updates_) / std::chrono::duration<double>(span).count();
    rate_window_start_ = now;
    rate_window_updates_ = 0;
  }
}

std::string encoding_name(std::int32_t rfb_encoding) {
  switch (static_cast<std::uint32_t>(rfb_encoding)) {
    case rfbEncodingRaw: return "raw";
    case rfbEncodingRRE: return "rre";
    case rfbEncodingCoRRE: return "corre";
    case rfbEncodingHextile: return "hextile";
    case rfbEncodingZlib: return "zlib";
    case rfbEncodingTight: return "tight";
    case rfbEncodingUltra: return "ultra";
    case rfbEncodingTRLE: return "trle";
    case rfbEncodingZRLE: return "zrle";
    case rfbEncodingZYWRLE: return "zywrle";
    case rfbEncodingTightPng: return "tightpng";
    default: return "other";
  }
}

ClientStreamStatus ClientStreamer::status(int id, TimePoint now, std::int32_t rfb_encoding) const {
  ClientStreamStatus s;
  s.id = id;
  // What the client really gets: a client that asked for ZRLE only is sent ZRLE, not Tight.
  s.encoding = h264_ ? "h264" : encoding_name(rfb_encoding);
  // A quality only where one applies: Tight's JPEG, and H.264's configured level; none for the lossless ones.
  const bool has_quality = h264_ || static_cast<std::uint32_t>(rfb_encoding) == rfbEncodingTight;
  s.continuous_updates = protocol_.continuous;
  s.fence = protocol_.offers_fence;
  if (const auto base = congestion_.base_rtt()) s.base_rtt_ms = static_cast<double>(base->count()) / 1000.0;
  if (const auto last = congestion_.last_rtt()) s.last_rtt_ms = static_cast<double>(last->count()) / 1000.0;
  s.window_bytes = congestion_.window();
  s.in_flight_bytes = congestion_.in_flight(now);
  s.updates_sent = updates_sent_;
  s.updates_held = updates_held_;
  s.update_requests = protocol_.update_requests;
  const auto level = has_quality ? tight_quality() : std::nullopt;
  s.quality = level ? level->jpeg_quality : 0;
  // What the client asked for, whether or not the server's cap let it have it.
  s.requested_quality = request_.jpeg_quality >= 1 && request_.jpeg_quality <= 100 ? request_.jpeg_quality : 0;
  s.requested_quality_level = request_.quality_level;
  s.compress_level = request_.compress_level;
  s.quality_level =
      has_quality && protocol_.continuous && config_.adaptive_quality ? static_cast<int>(quality_.level()) : 0;
  s.delivery_mbit = congestion_.path_rate() * 8.0 / 1e6;
  // An fps that stopped being refreshed (no updates for a while) is stale: age it out.
  s.fps = now - rate_window_start_ > std::chrono::seconds(2) ? 0.0 : fps_;
  return s;
}

}  // namespace rfbsim::detail
