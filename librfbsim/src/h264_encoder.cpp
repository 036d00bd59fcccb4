// SPDX-License-Identifier: GPL-2.0-or-later
// H264Encoder: libswscale turns RGBA into BT.601 limited-range 4:2:0, libx264 (through libavcodec) codes it.
#include "h264_encoder.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace rfbsim::detail {

namespace {

// ---- Choices, measured on this project's 2-core x86-64 build host (Debian 12, FFmpeg 5.1, x264 0.164) ----
//
// The sample: 60 pictures of a synthetic walk at 1280x720 (camera moving 1.5 m/s over a textured floor,
// buildings, six moving figures: every pixel changes every picture), SSIM on luma against the source.
// JPEG quality 80 (libjpeg, 4:2:0) makes 115.9 kB a picture at SSIM 0.9829. H.264 P pictures:
//   ultrafast CRF 22: 35.8 kB, SSIM 0.9834, ~5.0 ms a picture (0.31 of JPEG's bytes)
//   ultrafast CRF 23: 32.4 kB, SSIM 0.9802, ~4.9 ms
//   superfast CRF 23: 28.9 kB, SSIM 0.9853, ~6.7 ms (0.25 of JPEG's bytes)
//   superfast CRF 24: 26.2 kB, SSIM 0.9829, ~6.5 ms                          <- the default
//   superfast CRF 26: 20.9 kB, SSIM 0.9763
// (times: fastest of 236 interleaved pictures, colour conversion included, on a loaded host.)
// Superfast costs ~1.5 ms more a picture than ultrafast at equal SSIM, for 20-25% fewer bytes, and under a
// cap it keeps far more of the picture (deblocking, sub-pixel motion): capped at 2 Mbit/s, SSIM 0.935
// against ultrafast's 0.905. On this synthetic walk CRF 23 keeps SSIM above JPEG's with room to spare and
// CRF 24 only just matches it; on the real warehouse walk (bench_network, 150 rendered frames) CRF 23 made
// 0.35 of JPEG q80's bytes at SSIM +0.0020 and CRF 24 0.32 at +0.0010: CRF 24 is the default, the one that
// keeps both under a third of the bytes and at least JPEG's picture. The IDR of that walk is ~82 kB and takes
// ~20 ms.

constexpr int kMinSide = 16;                 // one macroblock
constexpr int kMaxFps = 240;
constexpr int kGopSeconds = 10;              // an IDR at least this often even if nobody asks
constexpr int kMinCapBps = 100'000;          // x264 holds even this, but the 720p walk is mush (SSIM 0.56)
constexpr int kLowestLevel = 31;

// ---- H.264 levels (ITU-T H.264 Table A-1); bit rates for the Baseline/Main factor (1000 bit/s) ----

struct Level {
  int idc;
  long max_mbps;    // macroblocks per second
  long max_fs;      // macroblocks per frame
  int max_kbps;     // kbit/s
  int max_cpb_kb;   // kbit
};

constexpr std::array<Level, 16> kLevels{{
    {10, 1485, 99, 64, 175},
    {11, 3000, 396, 192, 500},
    {12, 6000, 396, 384, 1000},
    {13, 11880, 396, 768, 2000},
    {20, 11880, 396, 2000, 2000},
    {21, 19800, 792, 4000, 4000},
    {22, 20250, 1620, 4000, 4000},
    {30, 40500, 1620, 10000, 10000},
    {31, 108000, 3600, 14000, 14000},
    {32, 216000, 5120, 20000, 20000},
    {40, 245760, 8192, 20000, 25000},
    {41, 245760, 8192, 50000, 62500},
    {42, 522240, 8704, 50000, 62500},
    {50, 589824, 22080, 135000, 135000},
    {51, 983040, 36864, 240000, 240000},
    {52, 2073600, 36864, 240000, 240000},
}};

const Level* find_level(int width, int height, int fps) {
  if (width <= 0 || height <= 0 || fps <= 0) return nullptr;
  const long mb_w = (width + 15) / 16;
  const long mb_h = (height + 15) / 16;
  const long frame_mbs = mb_w * mb_h;
  for (const Level& level : kLevels) {
    if (level.idc < kLowestLevel) continue;
    // Frame size, and each side at most sqrt(8 * MaxFS) macroblocks; then the macroblock rate.
    if (frame_mbs > level.max_fs || mb_w * mb_w > 8 * level.max_fs || mb_h * mb_h > 8 * level.max_fs) continue;
    if (frame_mbs * fps > level.max_mbps) continue;
    return &level;
  }
  return nullptr;
}

// ---- Ownership: one deleter per libav object ----

struct CodecCloser {
  void operator()(AVCodecContext* context) const { avcodec_free_context(&context); }
};
struct FrameCloser {
  void operator()(AVFrame* frame) const { av_frame_free(&frame); }
};
struct PacketCloser {
  void operator()(AVPacket* packet) const { av_packet_free(&packet); }
};
struct ScalerCloser {
  void operator()(SwsContext* scaler) const { sws_freeContext(scaler); }
};

std::string av_error(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

std::string size_text(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

[[noreturn]] void fail(const std::string& what) { throw std::runtime_error("H264Encoder: " + what); }

void set_option(void* object, const char* key, const std::string& value) {
  const int error = av_opt_set(object, key, value.c_str(), 0);
  if (error < 0) fail(std::string("libx264 option ") + key + "=" + value + " refused (" + av_error(error) + ")");
}

}  // namespace

struct H264Encoder::Av {
  std::unique_ptr<AVCodecContext, CodecCloser> codec;
  std::unique_ptr<AVFrame, FrameCloser> frame;
  std::unique_ptr<AVPacket, PacketCloser> packet;
  std::unique_ptr<SwsContext, ScalerCloser> scaler;
};

bool h264_available() { return avcodec_find_encoder_by_name("libx264") != nullptr; }

std::vector<int> h264_nal_types(const std::uint8_t* data, std::size_t size) {
  std::vector<int> types;
  // Every 00 00 01 starts a NAL unit (a 4-byte start code is a zero byte, then the same three).
  for (std::size_t i = 0; i + 3 < size; ++i) {
    if (data[i] == 0 && data[i + 1] == 0 && data[i + 2] == 1) {
      types.push_back(data[i + 3] & 0x1F);
      i += 2;
    }
  }
  return types;
}

int h264_level_idc(int width, int height, int fps) {
  const Level* level = find_level(width, height, fps);
  return level == nullptr ? 0 : level->idc;
}

H264Encoder::H264Encoder(int width, int height, int fps, const H264Tuning& tuning)
    : width_(width), height_(height), fps_(fps), vbv_seconds_(tuning.vbv_seconds), av_(std::make_unique<Av>()) {
  // ---- Check what was asked for ----
  if (fps < 1 || fps > kMaxFps) fail("fps " + std::to_string(fps) + " is outside 1.." + std::to_string(kMaxFps));
  if (width % 2 != 0 || height % 2 != 0) {
    fail("size " + size_text(width, height) + " has an odd side; H.264 4:2:0 needs even width and height");
  }
  if (width < kMinSide || height < kMinSide) {
    fail("size " + size_text(width, height) + " is too small (at least " + size_text(kMinSide, kMinSide) + ")");
  }
  const Level* level = find_level(width, height, fps);
  if (level == nullptr) {
    fail("size " + size_text(width, height) + " at " + std::to_string(fps) +
         " fps is too large for H.264 level 5.2 (at most 36864 macroblocks a frame, 2073600 a second)");
  }
  level_idc_ = level->idc;
  level_max_bitrate_ = level->max_kbps * 1000;
  level_max_buffer_ = level->max_cpb_kb * 1000;
  max_bitrate_ = level_max_bitrate_;

  const AVCodec* x264 = avcodec_find_encoder_by_name("libx264");
  if (x264 == nullptr) {
    fail(std::string("this libavcodec (") + LIBAVCODEC_IDENT + ") has no libx264 encoder; install one built with it");
  }

  // ---- The codec context: size, clock, colour, GOP, level ----
  av_->codec.reset(avcodec_alloc_context3(x264));
  if (!av_->codec) fail("out of memory for the codec context");
  AVCodecContext* c = av_->codec.get();
  c->width = width;
  c->height = height;
  c->pix_fmt = AV_PIX_FMT_YUV420P;
  c->time_base = AVRational{1, fps};
  c->framerate = AVRational{fps, 1};
  c->gop_size = kGopSeconds * fps;
  c->max_b_frames = 0;
  c->thread_count = 1;  // x264 frame threads delay output by a frame each; sliced threads cut slices
  c->level = level_idc_;
  // No AV_CODEC_FLAG_GLOBAL_HEADER: the wrapper then has x264 repeat SPS and PPS in front of every IDR.
  // The pixels are sRGB (BT.709 primaries, sRGB transfer), coded with the BT.601 matrix in limited range:
  // the matrix browsers assume when a stream says nothing, and said here anyway (VUI) so none guesses.
  c->color_primaries = AVCOL_PRI_BT709;
  c->color_trc = AVCOL_TRC_IEC61966_2_1;
  c->colorspace = AVCOL_SPC_SMPTE170M;
  c->color_range = AVCOL_RANGE_MPEG;
  // x264's info lines (CPU flags, profile, per-stream statistics at close) would print for every client;
  // shift this context's messages one level down: info becomes verbose (hidden), warnings stay visible.
  c->log_level_offset = AV_LOG_VERBOSE - AV_LOG_INFO;
  // VBV on from the start (x264 can retune a VBV later, but never switch one on): the level's limits.
  c->rc_max_rate = level_max_bitrate_;
  c->rc_buffer_size = level_max_buffer_;

  // ---- libx264's own options; x264-params is applied last, so it wins over the preset ----
  set_option(c->priv_data, "preset", tuning.preset);
  set_option(c->priv_data, "profile", "baseline");  // x264 baseline = constrained baseline (constraint_set1)
  set_option(c->priv_data, "crf", std::to_string(tuning.crf));
  set_option(c->priv_data, "forced-idr", "1");  // a forced key frame is an IDR, not an open-GOP I picture
  set_option(c->priv_data, "x264-params",
             "bframes=0:rc-lookahead=0:sync-lookahead=0:mbtree=0"  // each picture out before the next in
             ":threads=1:sliced-threads=0:slices=1:slice-max-size=0:slice-max-mbs=0"  // one slice
             ":repeat-headers=1:annexb=1:aud=0"  // SPS+PPS before each IDR, start codes, no delimiters
             ":scenecut=0:force-cfr=1"  // IDRs only when asked for (or after kGopSeconds); fps as given
             ":chromaloc=1");  // chroma samples centred between luma samples, as swscale makes them

  const int error = avcodec_open2(c, x264, nullptr);
  if (error < 0) {
    fail("avcodec_open2(libx264, " + size_text(width, height) + " at " + std::to_string(fps) +
         " fps) failed: " + av_error(error));
  }

  // ---- The picture x264 reads, its packet, and the RGBA -> YUV converter ----
  av_->frame.reset(av_frame_alloc());
  av_->packet.reset(av_packet_alloc());
  if (!av_->frame || !av_->packet) fail("out of memory for the frame or packet");
  AVFrame* f = av_->frame.get();
  f->format = AV_PIX_FMT_YUV420P;
  f->width = width;
  f->height = height;
  f->color_primaries = c->color_primaries;
  f->color_trc = c->color_trc;
  f->colorspace = c->colorspace;
  f->color_range = c->color_range;
  if (const int e = av_frame_get_buffer(f, 0); e < 0) fail("no memory for a YUV frame: " + av_error(e));

  // Chroma from every pixel, then averaged 2x2 (centre-sited, as the VUI says): measured at 720p, 1.2 ms a
  // picture against 2.1 ms for swscale's default half-width path, whose chroma is also ~0.1 level low.
  av_->scaler.reset(sws_getContext(width, height, AV_PIX_FMT_RGBA, width, height, AV_PIX_FMT_YUV420P,
                                   SWS_BILINEAR | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INP, nullptr, nullptr,
                                   nullptr));
  if (!av_->scaler) fail("swscale cannot convert RGBA to yuv420p at " + size_text(width, height));
  // Full-range RGB in; BT.601 matrix, limited range (16..235) out.
  const int* bt601 = sws_getCoefficients(SWS_CS_ITU601);
  if (sws_setColorspaceDetails(av_->scaler.get(), bt601, 1, bt601, 0, 0, 1 << 16, 1 << 16) < 0) {
    fail("swscale refused the BT.601 limited-range conversion");
  }
}

H264Encoder::~H264Encoder() = default;

std::vector<std::uint8_t> H264Encoder::encode(const std::uint8_t* rgba, int stride_bytes, bool force_idr) {
  assert(rgba != nullptr && "H264Encoder::encode: no pixels");
  assert(stride_bytes >= width_ * 4 && "H264Encoder::encode: stride shorter than a row");
  const auto start = std::chrono::steady_clock::now();
  AVCodecContext* c = av_->codec.get();
  AVFrame* f = av_->frame.get();
  AVPacket* p = av_->packet.get();

  // ---- RGBA -> YUV 4:2:0, into a buffer nobody else holds ----
  if (const int e = av_frame_make_writable(f); e < 0) fail("no writable YUV frame: " + av_error(e));
  const std::uint8_t* const source[4] = {rgba, nullptr, nullptr, nullptr};
  const int source_stride[4] = {stride_bytes, 0, 0, 0};
  sws_scale(av_->scaler.get(), source, source_stride, 0, height_, f->data, f->linesize);

  // ---- One picture in, its packet out at once (no B-frames, lookahead or threads can hold it back) ----
  f->pts = static_cast<std::int64_t>(frames_encoded_);
  f->pict_type = (force_idr || frames_encoded_ == 0) ? AV_PICTURE_TYPE_I : AV_PICTURE_TYPE_NONE;
  if (const int e = avcodec_send_frame(c, f); e < 0) fail("libx264 refused a picture: " + av_error(e));
  const int e = avcodec_receive_packet(c, p);
  if (e == AVERROR(EAGAIN)) fail("libx264 held a picture back (delayed output): the low-latency setup failed");
  if (e < 0) fail("libx264 produced no packet: " + av_error(e));
  std::vector<std::uint8_t> access_unit(p->data, p->data + p->size);
  av_packet_unref(p);
  if (access_unit.empty()) fail("libx264 produced an empty packet");

  // ---- Book-keeping ----
  const std::vector<int> types = h264_nal_types(access_unit.data(), access_unit.size());
  last_was_idr_ = std::find(types.begin(), types.end(), 5) != types.end();
  ++frames_encoded_;
  last_encode_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return access_unit;
}

void H264Encoder::set_max_bitrate(int bits_per_second) {
  assert(bits_per_second >= 0 && "H264Encoder::set_max_bitrate: negative rate");
  if (bits_per_second <= 0) {
    max_bitrate_ = level_max_bitrate_;
  } else {
    max_bitrate_ = std::clamp(bits_per_second / 1000 * 1000, kMinCapBps, level_max_bitrate_);
  }
  apply_cap();
}

// libavcodec's libx264 wrapper compares rc_max_rate and rc_buffer_size with x264's VBV before each picture
// and calls x264_encoder_reconfig when they differ, so the new cap governs the next encode().
void H264Encoder::apply_cap() {
  AVCodecContext* c = av_->codec.get();
  long buffer = level_max_buffer_;
  if (max_bitrate_ < level_max_bitrate_) {
    // At least one picture's share of the rate (x264 would raise it to that), at most the level's CPB.
    const double seconds = std::max(vbv_seconds_, 1.0 / fps_);
    buffer = std::min<long>(level_max_buffer_, std::lround(max_bitrate_ * seconds / 1000.0) * 1000 + 1000);
  }
  c->rc_max_rate = max_bitrate_;
  c->rc_buffer_size = static_cast<int>(buffer);
}

}  // namespace rfbsim::detail
