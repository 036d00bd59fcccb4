// SPDX-License-Identifier: GPL-2.0-or-later
// H264Encoder: RGBA frames in, H.264 pictures out, for the open RFB H.264 rectangle (encoding 50).
//
// noVNC (>= 1.6) hands each picture of that rectangle to the browser's WebCodecs decoder. What it accepts
// shapes every choice here: Annex B start codes, SPS and PPS in front of every IDR (the decoder is configured
// from the SPS), exactly one slice per picture (noVNC cuts the payload into chunks at each slice), no
// access unit delimiters, constrained baseline (avc1.42C0xx). The encoder is libx264 through libavcodec,
// set up so that every encode() returns its own picture at once: no B-frames, no lookahead, one thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace rfbsim::detail {

/// True when this process's libavcodec has the libx264 encoder (the only one H264Encoder uses).
[[nodiscard]] bool h264_available();

/// The nal_unit_type (0..31) of each NAL unit in an Annex B buffer, in order (3- or 4-byte start codes;
/// bytes before the first start code are skipped). 7 = SPS, 8 = PPS, 5 = IDR slice, 1 = other slice, 6 = SEI.
[[nodiscard]] std::vector<int> h264_nal_types(const std::uint8_t* data, std::size_t size);

/// The level_idc (31 = level 3.1) the encoder signals for width x height pixels at `fps` pictures per
/// second: the lowest level from 3.1 up whose frame size, macroblock rate and side limits fit; 0 when not
/// even level 5.2 fits. 1280x720@30 -> 31, 1920x1080@30 -> 40, 3840x2160@30 -> 51. Never below 3.1
/// (what browsers' H.264 support checks ask about): the uncapped stream is held to the level's maximum
/// bit rate, and level 1's 64 kbit/s would starve even a small picture.
[[nodiscard]] int h264_level_idc(int width, int height, int fps);

/// Knobs with good defaults; the server keeps the defaults, benchmarks and tests may change them.
struct H264Tuning {
  /// x264 constant rate factor, 0..51 (lower = better and bigger); the measurements behind 23 are in
  /// h264_encoder.cpp.
  double crf = 24.0;
  /// x264 speed preset. "superfast": ~1.5 ms a 720p picture more than "ultrafast" for 20-25% fewer bytes
  /// at equal SSIM, and much better pictures under a cap (see the .cpp).
  std::string preset = "superfast";
  /// VBV buffer under a set_max_bitrate() cap, in seconds of the cap: the longest burst (an IDR) the
  /// link must absorb above its rate. Small = low latency after an IDR, at the cost of that IDR's quality.
  double vbv_seconds = 0.25;
};

/// One H.264 stream of fixed-size pictures. Not thread-safe: one thread (the server's network thread)
/// calls everything. Owns its libavcodec encoder, swscale converter, frame and packet; frees them on
/// destruction. Memory: ~22 MB at 1280x720 (x264's reference, scratch and padded pictures).
class H264Encoder {
 public:
  /// Opens libx264 for `width` x `height` pictures at `fps` pictures per second (sets the level and the
  /// VBV's per-frame budget; the pictures may in fact come slower). Throws std::runtime_error naming the
  /// cause: no libx264 in this libavcodec, odd or out-of-range size (4:2:0 needs even sides, at least
  /// 16x16, at most what level 5.2 allows), fps outside 1..240, or avcodec_open2's error text.
  H264Encoder(int width, int height, int fps, const H264Tuning& tuning = {});
  ~H264Encoder();
  H264Encoder(const H264Encoder&) = delete;
  H264Encoder& operator=(const H264Encoder&) = delete;

  /// Encodes one RGBA picture (4 bytes a pixel, red first, top row first; `stride_bytes` >= width * 4
  /// between rows; `rgba` not null) and returns its access unit: Annex B, one slice, never empty.
  /// An IDR with SPS and PPS in front when `force_idr` is true or this is the first picture; otherwise a
  /// P picture (x264 itself starts an IDR only after 10 s worth of pictures, counted at `fps`, and never
  /// at a scene cut). Throws std::runtime_error if libavcodec refuses the picture (the encoder is then
  /// unusable: drop it and make another).
  std::vector<std::uint8_t> encode(const std::uint8_t* rgba, int stride_bytes, bool force_idr);

  /// Caps the stream at `bits_per_second` (VBV max rate) from the next encode() on; 0 = no cap beyond
  /// the level's maximum. Values are rounded down to whole kbit/s, raised to at least 100 kbit/s and
  /// lowered to at most the level's maximum bit rate.
  void set_max_bitrate(int bits_per_second);

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  /// The level_idc written in the SPS (see h264_level_idc).
  [[nodiscard]] int level_idc() const { return level_idc_; }
  /// The cap in force, bits per second (the level's maximum when uncapped).
  [[nodiscard]] int max_bitrate() const { return max_bitrate_; }
  /// Whether the last encode() returned an IDR picture.
  [[nodiscard]] bool last_was_idr() const { return last_was_idr_; }
  /// Pictures encoded since construction.
  [[nodiscard]] std::uint64_t frames_encoded() const { return frames_encoded_; }
  /// Wall time of the last encode() (colour conversion plus encoding), milliseconds.
  [[nodiscard]] double last_encode_ms() const { return last_encode_ms_; }

 private:
  struct Av;  // libavcodec and swscale objects, each owned by a unique_ptr with its deleter
  void apply_cap();

  int width_;
  int height_;
  int fps_;
  int level_idc_ = 0;
  int level_max_bitrate_ = 0;  // bits per second
  int level_max_buffer_ = 0;   // bits (the level's CPB size)
  double vbv_seconds_;
  int max_bitrate_ = 0;        // bits per second in force
  bool last_was_idr_ = false;
  std::uint64_t frames_encoded_ = 0;
  double last_encode_ms_ = 0.0;
  std::unique_ptr<Av> av_;
};

}  // namespace rfbsim::detail
