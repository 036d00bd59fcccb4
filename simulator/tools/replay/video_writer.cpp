// SPDX-License-Identifier: GPL-2.0-or-later
// VideoWriter: FFmpeg's swscale, codec and format contexts, each owned by a unique_ptr.
#include "video_writer.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/dict.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <system_error>
#include <vector>

namespace rfbsim::replay {

namespace {

// ---- Ownership: one deleter per FFmpeg object ----

struct FormatCloser {
  void operator()(AVFormatContext* context) const {
    if (context->pb != nullptr && (context->oformat->flags & AVFMT_NOFILE) == 0) avio_closep(&context->pb);
    avformat_free_context(context);
  }
};
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
using FormatPtr = std::unique_ptr<AVFormatContext, FormatCloser>;
using CodecPtr = std::unique_ptr<AVCodecContext, CodecCloser>;
using FramePtr = std::unique_ptr<AVFrame, FrameCloser>;
using PacketPtr = std::unique_ptr<AVPacket, PacketCloser>;
using ScalerPtr = std::unique_ptr<SwsContext, ScalerCloser>;

std::string av_error(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

bool supports_yuv420p(const AVCodec* codec) {
  if (codec->pix_fmts == nullptr) return true;  // unknown: let the open decide
  for (const AVPixelFormat* f = codec->pix_fmts; *f != AV_PIX_FMT_NONE; ++f) {
    if (*f == AV_PIX_FMT_YUV420P) return true;
  }
  return false;
}

// libx264 first; then every other H.264 encoder this FFmpeg has that takes yuv420p from memory.
std::vector<const AVCodec*> h264_encoders() {
  std::vector<const AVCodec*> found;
  const AVCodec* x264 = avcodec_find_encoder_by_name("libx264");
  if (x264 != nullptr) found.push_back(x264);
  void* cursor = nullptr;
  while (const AVCodec* codec = av_codec_iterate(&cursor)) {
    if (codec != x264 && av_codec_is_encoder(codec) != 0 && codec->id == AV_CODEC_ID_H264 && supports_yuv420p(codec)) {
      found.push_back(codec);
    }
  }
  return found;
}

}  // namespace

struct VideoWriter::Impl {
  std::filesystem::path file;     // where the video goes
  std::filesystem::path partial;  // where it is written until finish()
  int width = 0, height = 0;      // encoded size (even)
  FormatPtr format;
  CodecPtr codec;
  AVStream* stream = nullptr;     // owned by `format`
  FramePtr frame;
  PacketPtr packet;
  ScalerPtr scaler;
  std::int64_t frames = 0;
  std::int64_t bytes = 0;
  bool finished = false;

  // Unfinished (a throw in the constructor, or no finish()): close, and remove what was written.
  ~Impl() { discard(); }

  void discard() {
    if (finished) return;
    finished = true;
    scaler.reset();
    codec.reset();
    format.reset();  // closes the file before it goes
    std::error_code ec;
    std::filesystem::remove(partial, ec);
  }

  [[noreturn]] void fail(const std::string& what) const { throw VideoError(file.string() + ": " + what); }

  // Opens the first encoder that accepts our settings; names each refusal when none does.
  void open_encoder(const VideoSettings& settings) {
    const std::vector<const AVCodec*> candidates = h264_encoders();
    std::string refusals;
    for (const AVCodec* candidate : candidates) {
      CodecPtr context(avcodec_alloc_context3(candidate));
      if (!context) throw VideoError("out of memory for the H.264 encoder");
      context->width = width;
      context->height = height;
      context->pix_fmt = AV_PIX_FMT_YUV420P;
      context->time_base = AVRational{1, settings.fps};
      context->framerate = AVRational{settings.fps, 1};
      context->gop_size = std::max(1, static_cast<int>(settings.keyframe_seconds * settings.fps + 0.5));
      // BT.709, limited range: what players assume for HD video; the scaler converts with the same matrix.
      context->colorspace = AVCOL_SPC_BT709;
      context->color_primaries = AVCOL_PRI_BT709;
      context->color_trc = AVCOL_TRC_BT709;
      context->color_range = AVCOL_RANGE_MPEG;
      if ((format->oformat->flags & AVFMT_GLOBALHEADER) != 0) context->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
      if (std::string(candidate->name) == "libx264") {
        av_opt_set(context->priv_data, "preset", settings.preset.c_str(), 0);
        av_opt_set_double(context->priv_data, "crf", settings.crf, 0);
      } else {
        // Encoders without a quality knob get a bit rate that keeps a 720p simulation legible (~2.8 Mbit/s).
        context->bit_rate = static_cast<std::int64_t>(width) * height * settings.fps / 10;
      }
      const int error = avcodec_open2(context.get(), candidate, nullptr);
      if (error == 0) {
        codec = std::move(context);
        return;
      }
      refusals += std::string(refusals.empty() ? "" : "; ") + candidate->name + ": " + av_error(error);
    }
    throw VideoError(std::string("no H.264 encoder in this FFmpeg (libavcodec ") + LIBAVCODEC_IDENT + ")" +
                     (refusals.empty() ? std::string(" has none") : " opens (" + refusals + ")") +
                     "; install FFmpeg's libavcodec with libx264");
  }

  // Sends `input` (null: drain) and writes every packet the encoder hands back.
  void encode(const AVFrame* input) {
    int error = avcodec_send_frame(codec.get(), input);
    if (error < 0) fail("the encoder refused a frame (" + av_error(error) + ")");
    while (true) {
      error = avcodec_receive_packet(codec.get(), packet.get());
      if (error == AVERROR(EAGAIN) || error == AVERROR_EOF) return;
      if (error < 0) fail("encoding failed (" + av_error(error) + ")");
      av_packet_rescale_ts(packet.get(), codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      bytes += packet->size;
      error = av_interleaved_write_frame(format.get(), packet.get());  // takes the packet's data
      if (error < 0) fail("cannot write (" + av_error(error) + ")");
    }
  }
};

VideoWriter::VideoWriter(const std::filesystem::path& file, const VideoSettings& settings) : impl_(std::make_unique<Impl>()) {
  // FFmpeg's own chatter (the encoder's statistics, the muxer's second pass) only when something fails.
  av_log_set_level(AV_LOG_ERROR);
  Impl& v = *impl_;
  v.file = file;
  v.partial = file;
  v.partial += ".partial";
  if (settings.width < 2 || settings.height < 2 || settings.fps < 1) {
    v.fail("bad video size or rate " + std::to_string(settings.width) + "x" + std::to_string(settings.height) + " at " +
           std::to_string(settings.fps) + " fps");
  }
  // 4:2:0 halves the chroma in both directions: an odd size loses its last column or row.
  v.width = settings.width & ~1;
  v.height = settings.height & ~1;

  // The container: MP4 whatever the file is called, written under the temporary name.
  AVFormatContext* format = nullptr;
  int error = avformat_alloc_output_context2(&format, nullptr, "mp4", v.partial.c_str());
  if (error < 0 || format == nullptr) throw VideoError("FFmpeg has no MP4 muxer (" + av_error(error) + ")");
  v.format.reset(format);

  v.open_encoder(settings);
  v.stream = avformat_new_stream(v.format.get(), nullptr);
  if (v.stream == nullptr) throw VideoError("out of memory for the video stream");
  v.stream->time_base = v.codec->time_base;
  v.stream->avg_frame_rate = AVRational{settings.fps, 1};
  v.stream->r_frame_rate = AVRational{settings.fps, 1};
  error = avcodec_parameters_from_context(v.stream->codecpar, v.codec.get());
  if (error < 0) v.fail("cannot set up the stream (" + av_error(error) + ")");

  error = avio_open(&v.format->pb, v.partial.c_str(), AVIO_FLAG_WRITE);
  if (error < 0) v.fail("cannot open for writing (" + av_error(error) + ")");
  // faststart: the index goes to the front at the end, so that a browser plays the file while it loads.
  AVDictionary* options = nullptr;  // freed at once: nothing between can throw
  av_dict_set(&options, "movflags", "+faststart", 0);
  error = avformat_write_header(v.format.get(), &options);
  av_dict_free(&options);
  if (error < 0) v.fail("cannot write the MP4 header (" + av_error(error) + ")");

  v.frame.reset(av_frame_alloc());
  v.packet.reset(av_packet_alloc());
  if (!v.frame || !v.packet) throw VideoError("out of memory for video frames");
  v.frame->format = AV_PIX_FMT_YUV420P;
  v.frame->width = v.width;
  v.frame->height = v.height;
  v.frame->color_range = AVCOL_RANGE_MPEG;
  v.frame->colorspace = AVCOL_SPC_BT709;
  error = av_frame_get_buffer(v.frame.get(), 0);
  if (error < 0) throw VideoError("out of memory for video frames (" + av_error(error) + ")");

  // RGBA -> YUV 4:2:0 at the same size, BT.709 limited range as tagged above.
  v.scaler.reset(sws_getContext(v.width, v.height, AV_PIX_FMT_RGBA, v.width, v.height, AV_PIX_FMT_YUV420P, SWS_BILINEAR,
                                nullptr, nullptr, nullptr));
  if (!v.scaler) throw VideoError("libswscale cannot convert RGBA to yuv420p");
  sws_setColorspaceDetails(v.scaler.get(), sws_getCoefficients(SWS_CS_DEFAULT), 1, sws_getCoefficients(SWS_CS_ITU709), 0, 0,
                           1 << 16, 1 << 16);
}

VideoWriter::~VideoWriter() = default;

void VideoWriter::write(const FrameView& frame) {
  Impl& v = *impl_;
  if (v.finished) throw VideoError(v.file.string() + ": already finished");
  if (frame.pixels == nullptr || frame.width < v.width || frame.height < v.height) {
    v.fail("frame of " + std::to_string(frame.width) + "x" + std::to_string(frame.height) + " is smaller than the video");
  }
  int error = av_frame_make_writable(v.frame.get());  // the encoder may still hold the last one
  if (error < 0) v.fail("no frame buffer (" + av_error(error) + ")");
  const std::uint8_t* const source[] = {frame.pixels, nullptr, nullptr, nullptr};
  const int stride[] = {static_cast<int>(frame.row_bytes()), 0, 0, 0};
  sws_scale(v.scaler.get(), source, stride, 0, v.height, v.frame->data, v.frame->linesize);
  v.frame->pts = v.frames++;
  v.encode(v.frame.get());
}

void VideoWriter::finish() {
  Impl& v = *impl_;
  if (v.finished) return;
  v.encode(nullptr);
  const int error = av_write_trailer(v.format.get());
  if (error < 0) v.fail("cannot write the MP4 index (" + av_error(error) + ")");
  v.format.reset();  // closes the file
  v.finished = true;
  std::error_code ec;
  std::filesystem::rename(v.partial, v.file, ec);
  if (ec) {
    std::filesystem::remove(v.partial, ec);
    v.fail("cannot put the video in place (" + ec.message() + ")");
  }
  v.bytes = static_cast<std::int64_t>(std::filesystem::file_size(v.file, ec));
}

void VideoWriter::discard() { impl_->discard(); }

std::string VideoWriter::encoder() const { return impl_->codec ? impl_->codec->codec->name : ""; }

std::int64_t VideoWriter::frames() const { return impl_->frames; }

std::int64_t VideoWriter::bytes() const { return impl_->bytes; }

}  // namespace rfbsim::replay
