// SPDX-License-Identifier: GPL-2.0-or-later
// ClientStreamer: the policy for one client's framebuffer updates. It decides when an update goes out
// (asked for by the client, or pushed with ContinuousUpdates while the congestion window allows), in
// which codec (Tight JPEG through libvncserver, or an H.264 rectangle written here), at which JPEG
// quality, and it pings after each pushed update so that the fences measure the link.
//
// The network thread calls, per pass: after_messages() once the client's messages were read,
// serve() to send what is due. Fence answers arrive through fence_answered() (from rfb_extension).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "adaptive_quality.hpp"
#include "client_quality.hpp"
#include "congestion_control.hpp"
#include "rfb_extension.hpp"
#include "rfbsim/server.hpp"

struct _rfbClientRec;

namespace rfbsim::detail {

class H264Encoder;

/// What every client's streamer shares: the server's settings.
struct StreamerConfig {
  int width = 0;              ///< framebuffer size in pixels
  int height = 0;
  int frame_rate = 30;        ///< frames per second the host submits
  int jpeg_quality = 80;      ///< the top JPEG quality (1..100); 0 = respect the client's level
  int subsampling = 1;        ///< libvncserver's Tight subsampling index for the top level (1 = 4:2:0)
  bool adaptive_quality = true;
  Codec codec = Codec::kAuto;
};

class ClientStreamer {
 public:
  using Clock = std::chrono::steady_clock;
  using TimePoint = Clock::time_point;

  /// What one serve() call sent.
  struct Sent {
    bool update = false;            ///< a framebuffer update went out
    std::uint64_t bytes = 0;        ///< its bytes, H.264 only (Tight is counted by the server's hooks)
    std::chrono::nanoseconds encode{0};  ///< H.264 encode and write time
  };

  explicit ClientStreamer(const StreamerConfig& config);
  ~ClientStreamer();
  ClientStreamer(const ClientStreamer&) = delete;
  ClientStreamer& operator=(const ClientStreamer&) = delete;

  /// The negotiated protocol state (rfb_extension writes the client's offers into it).
  StreamingState& protocol() { return protocol_; }
  /// A fence answer arrived: the pong of the oldest ping. False when no ping was outstanding.
  bool fence_answered(TimePoint now);
  /// After the client's messages were read: announces Fence and ContinuousUpdates once both are offered.
  void after_messages(_rfbClientRec* client);
  /// A new frame changed the picture (called once per applied frame with damage).
  void frame_changed(TimePoint now);
  /// Sends the update that is due, if the client wants one and the link can take it.
  Sent serve(_rfbClientRec* client, TimePoint now, const std::uint8_t* framebuffer);
  /// Tight only: the JPEG quality and subsampling index to impose on the next update (nullopt = the
  /// client's own level). Never above what the client asked for (client_requested()).
  [[nodiscard]] std::optional<QualityLevel> tight_quality() const;
  /// What the client asked for in its latest SetEncodings (read by the server's update hook before each
  /// update). Its JPEG quality, where lower than the server's, becomes the top of this client's ladder.
  void client_requested(const ClientQualityRequest& request);
  /// Counts bytes written by a Tight update (from the server's update hooks) into the stream position.
  void tight_update_written(TimePoint now, std::uint64_t bytes);
  /// A snapshot for status pages.
  /// `rfb_encoding`: the encoding libvncserver sends this client's updates in (rfbClientRec::preferredEncoding,
  /// the first of the client's SetEncodings it supports); named as it is unless H.264 took over.
  [[nodiscard]] ClientStreamStatus status(int id, TimePoint now, std::int32_t rfb_encoding) const;

 private:
  bool use_h264();
  Sent send_h264(_rfbClientRec* client, TimePoint now, const std::uint8_t* framebuffer);
  void ping(_rfbClientRec* client, TimePoint now);
  void offer_frame(TimePoint now, bool held);
  void count_update(TimePoint now);
  // The top level for this client (the server's quality and subsampling, lowered to what it asked for), and its
  // ladder's tuning.
  [[nodiscard]] QualityLevel client_top() const;
  [[nodiscard]] AdaptiveQualityConfig client_ladder_config() const;

  StreamerConfig config_;
  StreamingState protocol_;
  CongestionControl congestion_;
  AdaptiveQuality quality_;
  ClientQualityRequest request_;          // the client's own quality and compression (client_quality.hpp)
  std::unique_ptr<H264Encoder> encoder_;  // created on the first H.264 update
  bool h264_ = false;                     // this client's updates are H.264 from now on
  bool h264_failed_ = false;              // the encoder could not be created: Tight for good
  bool new_frame_ = false;                // a frame changed the picture since the last serve()
  bool still_refresh_ = false;            // the next Tight update is the still picture at top quality
  std::uint64_t updates_sent_ = 0;
  std::uint64_t updates_held_ = 0;
  std::optional<TimePoint> last_hold_;    // when congestion last held a new frame back
  TimePoint rate_window_start_{};
  std::uint64_t rate_window_updates_ = 0;
  double fps_ = 0;
};

/// An RFB encoding's name as status pages show it: "tight", "zrle", "hextile", "raw", "zlib", "trle", "zywrle",
/// "rre", "corre", "ultra", "tightpng"; "other" for one this list lacks.
std::string encoding_name(std::int32_t rfb_encoding);

}  // namespace rfbsim::detail
