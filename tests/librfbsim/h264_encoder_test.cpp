// SPDX-License-Identifier: GPL-2.0-or-later
// H264Encoder: what it writes is parsed NAL by NAL and decoded back with libavcodec's own H.264 decoder.
#include "h264_encoder.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/frame.h>
#include <libswscale/swscale.h>
}

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "skip.hpp"

using rfbsim::detail::H264Encoder;
using rfbsim::detail::h264_available;
using rfbsim::detail::h264_level_idc;
using rfbsim::detail::h264_nal_types;

namespace {

using Bytes = std::vector<std::uint8_t>;

// ---- Synthetic pictures ----

// A smooth gradient (red across, green down, blue against both) with a 16x16 square moving right.
Bytes gradient_with_square(int width, int height, int t) {
  Bytes rgba(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4U);
  const int side = 16;
  const int square_x = (4 + 3 * t) % (width - side);
  const int square_y = (height - side) / 2;
  std::uint8_t* p = rgba.data();
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x, p += 4) {
      const bool in_square = x >= square_x && x < square_x + side && y >= square_y && y < square_y + side;
      p[0] = in_square ? 240 : static_cast<std::uint8_t>(x * 255 / (width - 1));
      p[1] = in_square ? 240 : static_cast<std::uint8_t>(y * 255 / (height - 1));
      p[2] = in_square ? 40 : static_cast<std::uint8_t>(255 - (x + y) * 255 / (width + height - 2));
      p[3] = 255;
    }
  }
  return rgba;
}

// Every pixel random every picture: the most bits an encoder can be asked for.
Bytes noise(int width, int height, std::uint32_t seed) {
  Bytes rgba(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4U);
  std::uint32_t state = seed * 2654435761U + 1U;
  for (std::size_t i = 0; i < rgba.size(); ++i) {
    state = state * 1664525U + 1013904223U;
    rgba[i] = (i % 4 == 3) ? 255 : static_cast<std::uint8_t>(state >> 24);
  }
  return rgba;
}

// ---- Reading what the encoder wrote ----

// The NAL units that carry a slice (1 = non-IDR, 5 = IDR).
int slices(const std::vector<int>& types) {
  int n = 0;
  for (const int type : types) n += (type == 1 || type == 5) ? 1 : 0;
  return n;
}

// The three bytes after the SPS's NAL header: profile_idc, the constraint flags, level_idc.
struct SpsHead {
  int profile_idc = -1;
  int constraint_flags = -1;
  int level_idc = -1;
};
SpsHead first_sps(const Bytes& au) {
  for (std::size_t i = 0; i + 6 < au.size(); ++i) {
    if (au[i] == 0 && au[i + 1] == 0 && au[i + 2] == 1 && (au[i + 3] & 0x1F) == 7) {
      return SpsHead{au[i + 4], au[i + 5], au[i + 6]};
    }
  }
  return {};
}

// ---- libavcodec's H.264 decoder, one packet in, one picture out, converted back to RGBA ----

struct CodecCloser {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct FrameCloser {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketCloser {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct ScalerCloser {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};

class Decoder {
 public:
  Decoder() {
    const AVCodec* h264 = avcodec_find_decoder(AV_CODEC_ID_H264);
    REQUIRE(h264 != nullptr);
    codec_.reset(avcodec_alloc_context3(h264));
    codec_->thread_count = 1;  // frame threads would hold pictures back
    REQUIRE(avcodec_open2(codec_.get(), h264, nullptr) == 0);
    frame_.reset(av_frame_alloc());
    packet_.reset(av_packet_alloc());
  }

  // Decodes one access unit; it must give exactly one picture, which comes back as RGBA. The conversion
  // uses the matrix and range the stream itself declares, as a browser would.
  Bytes decode(const Bytes& au, int width, int height) {
    REQUIRE(av_new_packet(packet_.get(), static_cast<int>(au.size())) == 0);
    std::memcpy(packet_->data, au.data(), au.size());
    REQUIRE(avcodec_send_packet(codec_.get(), packet_.get()) == 0);
    av_packet_unref(packet_.get());
    REQUIRE(avcodec_receive_frame(codec_.get(), frame_.get()) == 0);
    REQUIRE(frame_->width == width);
    REQUIRE(frame_->height == height);
    CHECK(frame_->format == AV_PIX_FMT_YUV420P);
    CHECK(frame_->colorspace == AVCOL_SPC_SMPTE170M);
    CHECK(frame_->color_range == AVCOL_RANGE_MPEG);
    CHECK(frame_->chroma_location == AVCHROMA_LOC_CENTER);
#ifdef AV_FRAME_FLAG_KEY
    last_key_ = (frame_->flags & AV_FRAME_FLAG_KEY) != 0;
#else
    last_key_ = frame_->key_frame != 0;
#endif
    if (!to_rgba_) {
      // Accurate rounding with full-width chroma: swscale's fast YUV -> RGB path reads a smooth gradient
      // ~1.2 levels dark, which would hide the encoder's own error.
      to_rgba_.reset(sws_getContext(width, height, static_cast<AVPixelFormat>(frame_->format), width, height,
                                    AV_PIX_FMT_RGBA, SWS_BILINEAR | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT,
                                    nullptr, nullptr, nullptr));
      REQUIRE(to_rgba_);
      const int* matrix = sws_getCoefficients(frame_->colorspace);
      const int full_range = frame_->color_range == AVCOL_RANGE_JPEG ? 1 : 0;
      sws_setColorspaceDetails(to_rgba_.get(), matrix, full_range, matrix, 1, 0, 1 << 16, 1 << 16);
    }
    Bytes rgba(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4U);
    std::uint8_t* const out[4] = {rgba.data(), nullptr, nullptr, nullptr};
    const int out_stride[4] = {width * 4, 0, 0, 0};
    sws_scale(to_rgba_.get(), frame_->data, frame_->linesize, 0, height, out, out_stride);
    av_frame_unref(frame_.get());
    // Nothing more: one access unit is one picture.
    CHECK(avcodec_receive_frame(codec_.get(), frame_.get()) == AVERROR(EAGAIN));
    return rgba;
  }

  bool last_key() const { return last_key_; }

 private:
  std::unique_ptr<AVCodecContext, CodecCloser> codec_;
  std::unique_ptr<AVFrame, FrameCloser> frame_;
  std::unique_ptr<AVPacket, PacketCloser> packet_;
  std::unique_ptr<SwsContext, ScalerCloser> to_rgba_;
  bool last_key_ = false;
};

// Mean absolute difference over R, G and B.
double mean_abs_diff(const Bytes& a, const Bytes& b) {
  REQUIRE(a.size() == b.size());
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;
    sum += std::abs(static_cast<int>(a[i]) - static_cast<int>(b[i]));
    ++n;
  }
  return sum / static_cast<double>(n);
}

// Mean absolute difference of BT.601 luma (0.299 R + 0.587 G + 0.114 B).
double luma_mad(const Bytes& a, const Bytes& b) {
  REQUIRE(a.size() == b.size());
  double sum = 0.0;
  for (std::size_t i = 0; i + 3 < a.size(); i += 4) {
    const double ya = 0.299 * a[i] + 0.587 * a[i + 1] + 0.114 * a[i + 2];
    const double yb = 0.299 * b[i] + 0.587 * b[i + 1] + 0.114 * b[i + 2];
    sum += std::abs(ya - yb);
  }
  return sum / static_cast<double>(a.size() / 4);
}

}  // namespace

TEST_CASE("h264_nal_types lists the NAL units of an Annex B buffer", "[h264]") {
  // Garbage before the first start code, a 4-byte start code, then 3-byte ones.
  const Bytes stream = {0x12, 0x00, 0x00, 0x00, 0x01, 0x67, 0x42, 0xC0, 0x1F, 0x00, 0x00, 0x01, 0x68, 0xCE,
                        0x00, 0x00, 0x01, 0x06, 0x05, 0x00, 0x00, 0x00, 0x01, 0x65, 0x88, 0x84};
  CHECK(h264_nal_types(stream.data(), stream.size()) == std::vector<int>{7, 8, 6, 5});
  CHECK(h264_nal_types(stream.data(), 0).empty());
  const Bytes no_start_code = {0x00, 0x00, 0x02, 0x41};
  CHECK(h264_nal_types(no_start_code.data(), no_start_code.size()).empty());
}

TEST_CASE("h264_level_idc picks the lowest level from 3.1 up that fits", "[h264]") {
  CHECK(h264_level_idc(64, 48, 30) == 31);       // tiny: 3.1 is the floor
  CHECK(h264_level_idc(1280, 720, 30) == 31);    // 3600 MBs, 108000 MB/s: exactly 3.1's limits
  CHECK(h264_level_idc(1280, 720, 60) == 32);    // 216000 MB/s
  CHECK(h264_level_idc(1920, 1080, 30) == 40);   // 8160 MBs (1088 lines)
  CHECK(h264_level_idc(1920, 1080, 60) == 42);   // 489600 MB/s
  CHECK(h264_level_idc(2560, 1440, 30) == 50);   // 14400 MBs
  CHECK(h264_level_idc(3840, 2160, 30) == 51);   // 32400 MBs, 972000 MB/s
  CHECK(h264_level_idc(3840, 2160, 60) == 52);
  CHECK(h264_level_idc(8192, 8192, 30) == 0);    // 262144 MBs: no level
  CHECK(h264_level_idc(4096, 16, 30) == 40);     // 256 MBs wide: 4.0 is the first with sqrt(8 * MaxFS) >= 256
  CHECK(h264_level_idc(8704, 16, 1) == 0);       // 544 MBs wide > sqrt(8 * 36864) = 543
}

TEST_CASE("H264Encoder refuses sizes H.264 4:2:0 cannot carry, naming the cause", "[h264]") {
  if (!h264_available()) RFBSIM_SKIP("this libavcodec has no libx264 encoder: H264Encoder not tested");
  CHECK_THROWS_WITH(H264Encoder(641, 480, 30), Catch::Contains("641x480") && Catch::Contains("even"));
  CHECK_THROWS_WITH(H264Encoder(640, 479, 30), Catch::Contains("odd"));
  CHECK_THROWS_WITH(H264Encoder(8, 8, 30), Catch::Contains("too small"));
  CHECK_THROWS_WITH(H264Encoder(16384, 16384, 30), Catch::Contains("too large"));
  CHECK_THROWS_WITH(H264Encoder(640, 480, 0), Catch::Contains("fps"));
  CHECK_THROWS_AS(H264Encoder(641, 480, 30), std::runtime_error);
  // A refusal inside libavcodec comes back with its own words, and nothing leaks on the way out.
  rfbsim::detail::H264Tuning warp;
  warp.preset = "warp9";
  CHECK_THROWS_WITH(H264Encoder(640, 480, 30, warp), Catch::Contains("avcodec_open2"));
}

TEST_CASE("H264Encoder writes one decodable constrained-baseline picture per call", "[h264]") {
  if (!h264_available()) RFBSIM_SKIP("this libavcodec has no libx264 encoder: H264Encoder not tested");
  // Bounds on the mean absolute difference, decoded vs source, RGB and BT.601 luma. At 720p the gradient
  // moves under 0.4 levels a pixel: 8-bit limited-range YUV rounds by under 0.5, CRF 23 barely touches a
  // smooth gradient; measured 0.61 (RGB) and 0.40 (luma). At 64x48 it climbs 4 levels a pixel and the
  // square's edges cover a tenth of the picture: 4:2:0 alone, without the codec, costs 2.6 there (a
  // swscale round trip), the codec brings it to 3.1..4.3, while luma, which keeps full resolution, stays
  // at 0.73..0.83. Each bound leaves ~1.5x the measurement.
  const auto [width, height, frames, rgb_bound, luma_bound] =
      GENERATE(std::make_tuple(64, 48, 12, 6.0, 1.25), std::make_tuple(1280, 720, 6, 1.0, 0.65));
  CAPTURE(width, height);
  H264Encoder encoder(width, height, 30);
  CHECK(encoder.level_idc() == 31);
  Decoder decoder;

  for (int t = 0; t < frames; ++t) {
    CAPTURE(t);
    const Bytes rgba = gradient_with_square(width, height, t);
    const Bytes au = encoder.encode(rgba.data(), width * 4, false);
    REQUIRE_FALSE(au.empty());
    const std::vector<int> types = h264_nal_types(au.data(), au.size());
    CHECK(slices(types) == 1);
    CHECK(encoder.frames_encoded() == static_cast<std::uint64_t>(t + 1));
    CHECK(encoder.last_encode_ms() > 0.0);

    if (t == 0) {
      // SPS, PPS, x264's SEI (its version, once per stream), the IDR slice.
      CHECK(types == std::vector<int>{7, 8, 6, 5});
      CHECK(encoder.last_was_idr());
      const SpsHead sps = first_sps(au);
      CHECK(sps.profile_idc == 66);                    // baseline...
      CHECK((sps.constraint_flags & 0x40) != 0);       // ...constrained (constraint_set1)
      CHECK(sps.level_idc == encoder.level_idc());
    } else {
      CHECK(types == std::vector<int>{1});
      CHECK_FALSE(encoder.last_was_idr());
    }

    // The picture decodes at once, and looks like its source (bounds above).
    const Bytes back = decoder.decode(au, width, height);
    CHECK(decoder.last_key() == (t == 0));
    CHECK(mean_abs_diff(rgba, back) < rgb_bound);
    CHECK(luma_mad(rgba, back) < luma_bound);
  }
}

TEST_CASE("H264Encoder starts an IDR with SPS and PPS when asked", "[h264]") {
  if (!h264_available()) RFBSIM_SKIP("this libavcodec has no libx264 encoder: H264Encoder not tested");
  const int width = 160, height = 96;
  H264Encoder encoder(width, height, 30);
  Decoder decoder;
  for (int t = 0; t < 8; ++t) {
    CAPTURE(t);
    const bool force = (t == 4);
    const Bytes rgba = gradient_with_square(width, height, t);
    const Bytes au = encoder.encode(rgba.data(), width * 4, force);
    const std::vector<int> types = h264_nal_types(au.data(), au.size());
    if (t == 0) {
      CHECK(types == std::vector<int>{7, 8, 6, 5});
    } else if (force) {
      CHECK(types == std::vector<int>{7, 8, 5});  // the SEI comes once per stream, not per IDR
      CHECK(encoder.last_was_idr());
    } else {
      CHECK(types == std::vector<int>{1});
    }
    const Bytes back = decoder.decode(au, width, height);
    CHECK(decoder.last_key() == (t == 0 || force));
    CHECK(mean_abs_diff(rgba, back) < 3.0);  // 160x96: measured up to 1.8 (RGB) and 0.7 (luma)
    CHECK(luma_mad(rgba, back) < 1.0);
  }
}

TEST_CASE("H264Encoder: a padded stride reads the same pixels", "[h264]") {
  if (!h264_available()) RFBSIM_SKIP("this libavcodec has no libx264 encoder: H264Encoder not tested");
  const int width = 64, height = 48, stride = width * 4 + 32;
  const Bytes tight = gradient_with_square(width, height, 0);
  Bytes padded(static_cast<std::size_t>(stride) * height, 0xEE);
  for (int y = 0; y < height; ++y) {
    std::memcpy(&padded[static_cast<std::size_t>(y) * stride], &tight[static_cast<std::size_t>(y) * width * 4],
                static_cast<std::size_t>(width) * 4U);
  }
  H264Encoder a(width, height, 30);
  H264Encoder b(width, height, 30);
  // x264 with one thread is deterministic: the same pixels make the same bytes.
  CHECK(a.encode(tight.data(), width * 4, false) == b.encode(padded.data(), stride, false));
}

TEST_CASE("H264Encoder::set_max_bitrate caps a busy stream from the next picture", "[h264]") {
  if (!h264_available()) RFBSIM_SKIP("this libavcodec has no libx264 encoder: H264Encoder not tested");
  const int width = 320, height = 240, fps = 30;
  H264Encoder encoder(width, height, fps);
  CHECK(encoder.max_bitrate() == 14'000'000);  // level 3.1's maximum
  Decoder decoder;
  std::uint32_t seed = 1;
  // Mean bytes per picture over `count` noisy pictures, after `settle` pictures the VBV may need to adapt.
  auto mean_bytes = [&](int settle, int count) {
    double total = 0.0;
    for (int i = 0; i < settle + count; ++i) {
      const Bytes rgba = noise(width, height, seed++);
      const Bytes au = encoder.encode(rgba.data(), width * 4, false);
      decoder.decode(au, width, height);  // every picture stays decodable
      if (i >= settle) total += static_cast<double>(au.size());
    }
    return total / count;
  };

  const double uncapped = mean_bytes(1, 10);
  const int cap = 400'000;
  encoder.set_max_bitrate(cap);
  CHECK(encoder.max_bitrate() == cap);
  const double next = mean_bytes(0, 1);  // the very next picture obeys (measured 1022 B against 29.5 kB)
  const double capped = mean_bytes(10, 20);
  encoder.set_max_bitrate(0);
  CHECK(encoder.max_bitrate() == 14'000'000);
  const double released = mean_bytes(5, 10);  // x264 eases its quantiser back over a few pictures
  INFO("uncapped " << uncapped << " B, next " << next << " B, capped " << capped << " B, released " << released
                    << " B a picture");
  CHECK(next < uncapped / 4.0);
  // Under the cap a picture gets its share of 400 kbit/s (1667 B at 30 fps); allow 20% for the VBV's slack.
  CHECK(capped < 1.2 * cap / 8.0 / fps);
  CHECK(capped < uncapped / 4.0);
  CHECK(released > 4.0 * capped);

  // Out-of-range caps are clamped to 100 kbit/s .. the level's maximum, in whole kbit/s.
  encoder.set_max_bitrate(1);
  CHECK(encoder.max_bitrate() == 100'000);
  encoder.set_max_bitrate(123'456'789);
  CHECK(encoder.max_bitrate() == 14'000'000);
  encoder.set_max_bitrate(250'999);
  CHECK(encoder.max_bitrate() == 250'000);
}
