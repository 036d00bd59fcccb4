// SPDX-License-Identifier: GPL-2.0-or-later
// H264RfbClient: the socket side (connect, handshake, a poll-driven read buffer), an incremental parser of
// server messages over that buffer, and per-rectangle H.264 decoders (libavcodec + libswscale).
#include "h264_rfb_client.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libswscale/swscale.h>
}

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <map>
#include <stdexcept>

#include "rfb_client_messages.hpp"

namespace rfbsim::test {

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::int32_t kEncodingRaw = 0;
constexpr std::int32_t kEncodingTight = 7;
constexpr std::int32_t kEncodingH264 = 50;
constexpr std::int32_t kEncodingFence = -312;
constexpr std::int32_t kEncodingContinuousUpdates = -313;

constexpr std::uint32_t kFenceBlockBefore = 1U << 0;
constexpr std::uint32_t kFenceBlockAfter = 1U << 1;
constexpr std::uint32_t kFenceRequest = 1U << 31;
constexpr std::size_t kMaxFencePayload = 64;

constexpr std::uint32_t kH264ResetContext = 1U << 0;
constexpr std::uint32_t kH264ResetAllContexts = 1U << 1;

constexpr std::uint32_t kMaxCutText = 64U << 20;      // bytes; more is taken as a desynchronised stream
constexpr std::uint32_t kMaxH264Payload = 256U << 20;  // bytes, likewise
constexpr std::size_t kMinReadRoom = 64U << 10;        // free bytes the read buffer offers each recv

// ---- Wire helpers: big-endian fields ----

std::uint32_t be16(const std::uint8_t* p) { return (std::uint32_t{p[0]} << 8) | p[1]; }
std::uint32_t be32(const std::uint8_t* p) { return (be16(p) << 16) | be16(p + 2); }

void put16(std::vector<std::uint8_t>& out, std::uint32_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  put16(out, v >> 16);
  put16(out, v & 0xffffU);
}


std::string rect_text(int x, int y, int w, int h) {
  return std::to_string(w) + "x" + std::to_string(h) + " at (" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

std::string av_error_text(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

// ---- Annex B: where each access unit (one picture, with the SPS/PPS/SEI in front of it) begins ----

struct AccessUnit {
  std::size_t begin = 0;  // first byte of its first start code
  std::size_t end = 0;    // one past its last byte
  bool has_picture = false;  // holds a slice (NAL type 1 or 5)
  bool idr = false;          // holds an IDR slice (NAL type 5)
};

// Splits an Annex B buffer at access-unit boundaries (H.264 7.4.1.2.3, simplified): after a slice, the next
// AUD, SPS, PPS, SEI, prefix NAL, or slice with first_mb_in_slice == 0 opens a new access unit. Bytes before
// the first start code are dropped.
std::vector<AccessUnit> split_access_units(const std::uint8_t* data, std::size_t size) {
  std::vector<AccessUnit> units;
  for (std::size_t i = 0; i + 3 < size; ++i) {
    if (data[i] != 0 || data[i + 1] != 0 || data[i + 2] != 1) continue;
    const std::size_t start = (i > 0 && data[i - 1] == 0) ? i - 1 : i;
    const std::size_t header = i + 3;
    const int type = data[header] & 0x1f;
    const bool slice = type == 1 || type == 5;
    // first_mb_in_slice is ue(v): value 0 is the single bit '1'.
    const bool first_slice = slice && header + 1 < size && (data[header + 1] & 0x80) != 0;
    const bool opens = type == 6 || type == 7 || type == 8 || type == 9 || (type >= 14 && type <= 18) || first_slice;
    if (units.empty() || (units.back().has_picture && opens)) {
      if (!units.empty()) units.back().end = start;
      units.push_back(AccessUnit{start, size, false, false});
    }
    units.back().has_picture = units.back().has_picture || slice;
    units.back().idr = units.back().idr || type == 5;
    i = header;
  }
  return units;
}

// ---- libavcodec objects with their deleters ----

struct CodecContextDeleter {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct FrameDeleter {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketDeleter {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
using CodecContextPtr = std::unique_ptr<AVCodecContext, CodecContextDeleter>;

// A rectangle, the key of its decoder (as noVNC keys its contexts).
struct RectKey {
  int x = 0;
  int y = 0;
  int w = 0;
  int h = 0;
  auto operator<=>(const RectKey&) const = default;
};

// Where decoded pictures go: the client's RGBA framebuffer.
struct Canvas {
  std::uint8_t* pixels = nullptr;
  int width = 0;
  int height = 0;
};

// What one rectangle's payload did.
struct DecodeTally {
  std::uint64_t pictures = 0;
  std::uint64_t idrs = 0;
  std::uint64_t errors = 0;
  std::string last_error;
};

}  // namespace

// One H.264 decoder per rectangle, created at the first picture for it; the colour converter is shared.
struct H264RfbClient::Decoders {
  struct Stream {
    CodecContextPtr codec;      // null until the next IDR after a reset or an error
    bool awaiting_idr = true;   // a context starts with an IDR; pictures before it cannot decode
  };

  const AVCodec* h264 = nullptr;
  std::map<RectKey, Stream> streams;
  std::unique_ptr<AVFrame, FrameDeleter> frame{av_frame_alloc()};
  std::unique_ptr<AVPacket, PacketDeleter> packet{av_packet_alloc()};
  SwsContext* sws = nullptr;
  // What sws was last set up for: source size, format, colour matrix and range; destination size.
  std::array<int, 7> sws_setup{};

  Decoders() {
    h264 = avcodec_find_decoder(AV_CODEC_ID_H264);
    if (h264 == nullptr) throw std::runtime_error("H264RfbClient: this libavcodec has no H.264 decoder");
    if (!frame || !packet) throw std::runtime_error("H264RfbClient: out of memory for libavcodec objects");
  }
  ~Decoders() { sws_freeContext(sws); }
  Decoders(const Decoders&) = delete;
  Decoders& operator=(const Decoders&) = delete;

  // Decodes one encoding-50 rectangle's payload and draws its pictures into the canvas.
  DecodeTally decode(const RectKey& key, std::uint32_t flags, const std::uint8_t* data, std::size_t size,
                     const Canvas& canvas) {
    DecodeTally tally;
    // The reset flags apply before the payload: drop every context, or this rectangle's.
    if ((flags & kH264ResetAllContexts) != 0) streams.clear();
    if ((flags & kH264ResetContext) != 0) streams.erase(key);
    if (size == 0) return tally;

    const auto units = split_access_units(data, size);
    if (units.empty()) {
      fail(tally, streams[key], "no Annex B start code in " + std::to_string(size) + " bytes");
      return tally;
    }
    Stream& stream = streams[key];
    for (const AccessUnit& unit : units) {
      if (unit.idr) ++tally.idrs;
      // Until an IDR comes, pictures cannot decode: count each, feed none (parameter sets alone are fine).
      if (stream.awaiting_idr && unit.has_picture && !unit.idr) {
        ++tally.errors;
        tally.last_error = "picture for " + rect_text(key.x, key.y, key.w, key.h) + " skipped: no IDR since reset";
        continue;
      }
      if (!stream.codec && !open(stream, tally)) return tally;
      if (unit.idr) stream.awaiting_idr = false;
      decode_unit(key, stream, data + unit.begin, unit.end - unit.begin, unit.has_picture, canvas, tally);
    }
    return tally;
  }

 private:
  // Counts an error and resets the stream: it waits for the next IDR on a fresh decoder.
  static void fail(DecodeTally& tally, Stream& stream, const std::string& why) {
    ++tally.errors;
    tally.last_error = why;
    stream.codec.reset();
    stream.awaiting_idr = true;
  }

  bool open(Stream& stream, DecodeTally& tally) {
    CodecContextPtr codec(avcodec_alloc_context3(h264));
    if (!codec) {
      fail(tally, stream, "avcodec_alloc_context3 failed");
      return false;
    }
    codec->thread_count = 1;                     // frame threads would hold pictures back
    codec->flags |= AV_CODEC_FLAG_LOW_DELAY;     // each access unit out as soon as it is in
    codec->flags &= ~AV_CODEC_FLAG_OUTPUT_CORRUPT;
    const int e = avcodec_open2(codec.get(), h264, nullptr);
    if (e < 0) {
      fail(tally, stream, "avcodec_open2: " + av_error_text(e));
      return false;
    }
    stream.codec = std::move(codec);
    return true;
  }

  // Feeds one access unit and draws what comes out; a picture that should come out and does not is an error.
  void decode_unit(const RectKey& key, Stream& stream, const std::uint8_t* data, std::size_t size,
                   bool has_picture, const Canvas& canvas, DecodeTally& tally) {
    // Not reference counted: avcodec_send_packet copies the bytes (with the padding it needs).
    packet->data = const_cast<std::uint8_t*>(data);
    packet->size = static_cast<int>(size);
    const int sent = avcodec_send_packet(stream.codec.get(), packet.get());
    packet->data = nullptr;
    packet->size = 0;
    if (sent < 0) {
      fail(tally, stream, "avcodec_send_packet: " + av_error_text(sent));
      return;
    }
    int pictures_out = 0;
    int e = 0;
    while ((e = avcodec_receive_frame(stream.codec.get(), frame.get())) == 0) {
      ++pictures_out;
      const bool drawn = draw(key, stream, canvas, tally);
      av_frame_unref(frame.get());
      if (!drawn) return;
    }
    if (e != AVERROR(EAGAIN) && e != AVERROR_EOF) {
      fail(tally, stream, "avcodec_receive_frame: " + av_error_text(e));
    } else if (has_picture && pictures_out == 0) {
      fail(tally, stream, "no picture out of an access unit for " + rect_text(key.x, key.y, key.w, key.h));
    }
  }

  // Converts the decoded picture to RGBA straight into the canvas at the rectangle.
  bool draw(const RectKey& key, Stream& stream, const Canvas& canvas, DecodeTally& tally) {
    const AVFrame& f = *frame;
    if (f.decode_error_flags != 0 || (f.flags & AV_FRAME_FLAG_CORRUPT) != 0) {
      fail(tally, stream, "corrupt picture for " + rect_text(key.x, key.y, key.w, key.h));
      return false;
    }
    if (f.width != key.w || f.height != key.h) {
      // The server's bug, not the stream's: the decoder is fine, the picture is not drawn.
      ++tally.errors;
      tally.last_error = "decoded " + std::to_string(f.width) + "x" + std::to_string(f.height) +
                         " for a rectangle " + rect_text(key.x, key.y, key.w, key.h);
      return true;
    }
    // The colour matrix and range the stream signals (BT.601 when unspecified, as the server encodes).
    const int colorspace = f.colorspace == AVCOL_SPC_UNSPECIFIED ? SWS_CS_ITU601 : static_cast<int>(f.colorspace);
    const int full_range = f.color_range == AVCOL_RANGE_JPEG ? 1 : 0;
    const std::array<int, 7> setup{f.width, f.height, f.format, colorspace, full_range, key.w, key.h};
    if (sws == nullptr || setup != sws_setup) {
      sws_freeContext(sws);
      sws = sws_getContext(f.width, f.height, static_cast<AVPixelFormat>(f.format), key.w, key.h, AV_PIX_FMT_RGBA,
                           SWS_BILINEAR, nullptr, nullptr, nullptr);
      if (sws == nullptr) {
        fail(tally, stream, "sws_getContext refused pixel format " + std::to_string(f.format));
        return false;
      }
      sws_setColorspaceDetails(sws, sws_getCoefficients(colorspace), full_range, sws_getCoefficients(SWS_CS_DEFAULT),
                               1, 0, 1 << 16, 1 << 16);
      sws_setup = setup;
    }
    const std::size_t row_bytes = static_cast<std::size_t>(canvas.width) * 4U;
    std::uint8_t* destination[4] = {
        canvas.pixels + static_cast<std::size_t>(key.y) * row_bytes + static_cast<std::size_t>(key.x) * 4U, nullptr,
        nullptr, nullptr};
    const int destination_stride[4] = {static_cast<int>(row_bytes), 0, 0, 0};
    sws_scale(sws, f.data, f.linesize, 0, f.height, destination, destination_stride);
    ++tally.pictures;
    return true;
  }
};

// ---- Connection and handshake ----

H264RfbClient::H264RfbClient(const std::string& host, int port, const H264RfbClientOptions& options)
    : options_(options), decoders_(std::make_unique<Decoders>()) {
  const auto deadline = Clock::now() + options_.handshake_timeout;
  const std::string where = host + ":" + std::to_string(port);

  // connect: every address of the name in turn, each without blocking past the deadline.
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const int lookup = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found);
  if (lookup != 0) {
    throw std::runtime_error("H264RfbClient: connect: cannot resolve " + where + ": " + gai_strerror(lookup));
  }
  std::string connect_error = "no address";
  for (const addrinfo* a = found; a != nullptr && fd_ < 0; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
    if (fd < 0) continue;
    int e = ::connect(fd, a->ai_addr, a->ai_addrlen) == 0 ? 0 : errno;
    if (e == EINPROGRESS) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
      pollfd pfd{fd, POLLOUT, 0};
      if (left > 0 && ::poll(&pfd, 1, static_cast<int>(left)) == 1) {
        socklen_t length = sizeof e;
        ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &e, &length);
      } else {
        e = ETIMEDOUT;
      }
    }
    if (e == 0) {
      fd_ = fd;
    } else {
      connect_error = std::strerror(e);
      ::close(fd);
    }
  }
  ::freeaddrinfo(found);
  if (fd_ < 0) throw std::runtime_error("H264RfbClient: connect to " + where + " failed: " + connect_error);
  const int one = 1;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);

  try {
    // ProtocolVersion: the server speaks first; this client speaks 3.8 only.
    const std::string version(reinterpret_cast<const char*>(read_exact(12, deadline, "ProtocolVersion")), 12);
    consume(12);
    if (version.compare(0, 4, "RFB ") != 0 || version < "RFB 003.008\n") {
      throw std::runtime_error("H264RfbClient: ProtocolVersion: the server offers '" + version.substr(0, 11) +
                               "', this client needs RFB 003.008");
    }
    const std::string ours = "RFB 003.008\n";
    if (!send_bytes({ours.begin(), ours.end()})) {
      throw std::runtime_error("H264RfbClient: ProtocolVersion: send failed");
    }

    // Security: a count then the types; a count of 0 is followed by the reason.
    const std::size_t count = *read_exact(1, deadline, "security types");
    consume(1);
    if (count == 0) {
      const std::uint32_t length = std::min(be32(read_exact(4, deadline, "security failure reason")), 4096U);
      consume(4);
      const std::string reason(reinterpret_cast<const char*>(read_exact(length, deadline, "security failure reason")),
                               length);
      throw std::runtime_error("H264RfbClient: security: the server refused: " + reason);
    }
    const std::uint8_t* types = read_exact(count, deadline, "security types");
    const bool none_offered = std::find(types, types + count, std::uint8_t{1}) != types + count;
    consume(count);
    if (!none_offered) throw std::runtime_error("H264RfbClient: security: the server does not offer None");
    if (!send_bytes({1})) throw std::runtime_error("H264RfbClient: security: send failed");

    // SecurityResult: 0 is OK; otherwise a reason follows (3.8).
    const std::uint32_t result = be32(read_exact(4, deadline, "SecurityResult"));
    consume(4);
    if (result != 0) {
      const std::uint32_t length = std::min(be32(read_exact(4, deadline, "SecurityResult reason")), 4096U);
      consume(4);
      const std::string reason(reinterpret_cast<const char*>(read_exact(length, deadline, "SecurityResult reason")),
                               length);
      throw std::runtime_error("H264RfbClient: SecurityResult: failed: " + reason);
    }

    // ClientInit (shared), then ServerInit: size, pixel format, name.
    if (!send_bytes({1})) throw std::runtime_error("H264RfbClient: ClientInit: send failed");
    const std::uint8_t* init = read_exact(24, deadline, "ServerInit");
    width_ = static_cast<int>(be16(init));
    height_ = static_cast<int>(be16(init + 2));
    const int bits_per_pixel = init[4];
    const bool true_colour = init[7] != 0;
    big_endian_ = init[6] != 0;
    red_max_ = be16(init + 8);
    green_max_ = be16(init + 10);
    blue_max_ = be16(init + 12);
    red_shift_ = init[14];
    green_shift_ = init[15];
    blue_shift_ = init[16];
    const std::uint32_t name_length = be32(init + 20);
    consume(24);
    if (bits_per_pixel != 32 || !true_colour || red_max_ == 0 || green_max_ == 0 || blue_max_ == 0 ||
        red_shift_ > 31 || green_shift_ > 31 || blue_shift_ > 31) {
      throw std::runtime_error("H264RfbClient: ServerInit: pixel format of " + std::to_string(bits_per_pixel) +
                               " bits per pixel" + (true_colour ? "" : ", colour map") +
                               "; this client needs 32 bits per pixel true colour");
    }
    if (name_length > 65536) throw std::runtime_error("H264RfbClient: ServerInit: desktop name of " +
                                                      std::to_string(name_length) + " bytes");
    desktop_name_.assign(reinterpret_cast<const char*>(read_exact(name_length, deadline, "ServerInit name")),
                         name_length);
    consume(name_length);
    pixels_.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4U, 0);

    // SetEncodings in order of preference, then the first, whole-screen request.
    std::vector<std::int32_t> encodings{kEncodingH264};
    if (options_.offer_tight) encodings.push_back(kEncodingTight);
    encodings.push_back(kEncodingRaw);
    if (options_.fence) encodings.push_back(kEncodingFence);
    if (options_.continuous_updates) encodings.push_back(kEncodingContinuousUpdates);
    std::vector<std::uint8_t> set_encodings{2, 0};
    put16(set_encodings, static_cast<std::uint32_t>(encodings.size()));
    for (const std::int32_t e : encodings) put32(set_encodings, static_cast<std::uint32_t>(e));
    if (!send_bytes(set_encodings)) throw std::runtime_error("H264RfbClient: SetEncodings: send failed");
    request_update(false);
    if (!connected()) throw std::runtime_error("H264RfbClient: FramebufferUpdateRequest: send failed");
  } catch (...) {
    ::close(fd_);
    fd_ = -1;
    throw;
  }
}

H264RfbClient::~H264RfbClient() {
  if (fd_ >= 0) ::close(fd_);
}

// ---- Socket side ----

void H264RfbClient::read_some(int timeout_ms) {
  if (fd_ < 0) return;
  pollfd pfd{fd_, POLLIN, 0};
  const int ready = ::poll(&pfd, 1, std::max(timeout_ms, 0));
  if (ready < 0 && errno != EINTR) close_connection(std::string("poll: ") + std::strerror(errno));
  if (ready <= 0) return;
  // Make room: move the unparsed bytes to the front, grow when a message needs more than is free.
  if (in_begin_ == in_end_) {
    in_begin_ = in_end_ = 0;
  } else if (in_.size() - in_end_ < kMinReadRoom && in_begin_ > 0) {
    std::memmove(in_.data(), in_.data() + in_begin_, in_end_ - in_begin_);
    in_end_ -= in_begin_;
    in_begin_ = 0;
  }
  if (in_.size() - in_end_ < kMinReadRoom) in_.resize(std::max(in_.size() * 2, in_end_ + kMinReadRoom));
  const auto n = ::recv(fd_, in_.data() + in_end_, in_.size() - in_end_, 0);
  if (n > 0) {
    in_end_ += static_cast<std::size_t>(n);
    bytes_received_ += static_cast<std::uint64_t>(n);
  } else if (n == 0) {
    close_connection("the server closed the connection");
  } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
    close_connection(std::string("recv: ") + std::strerror(errno));
  }
}

const std::uint8_t* H264RfbClient::read_exact(std::size_t n, Clock::time_point deadline, const char* step) {
  while (buffered() < n) {
    if (!connected()) throw std::runtime_error(std::string("H264RfbClient: ") + step + ": " + last_error_);
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) throw std::runtime_error(std::string("H264RfbClient: ") + step + ": timed out");
    read_some(static_cast<int>(left));
  }
  return in_data();
}

bool H264RfbClient::send_bytes(const std::vector<std::uint8_t>& bytes) {
  std::size_t sent = 0;
  while (fd_ >= 0 && sent < bytes.size()) {
    const auto n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      // The server reads nothing for 5 s: give up rather than hang a test.
      pollfd pfd{fd_, POLLOUT, 0};
      if (::poll(&pfd, 1, 5000) == 0) close_connection("send: the server has not read for 5 s");
    } else {
      close_connection(std::string("send: ") + std::strerror(errno));
    }
  }
  return fd_ >= 0;
}

void H264RfbClient::close_connection(const std::string& why) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  last_error_ = why;
}

void H264RfbClient::protocol_error(const std::string& what) {
  // The stream cannot be followed past bytes we do not understand: drop them with the connection.
  close_connection(what);
  in_begin_ = in_end_ = 0;
  rects_left_ = 0;
  throw std::runtime_error("H264RfbClient: protocol error: " + what);
}

bool H264RfbClient::pump_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  if (done()) return true;
  for (;;) {
    // Handle every whole message buffered (also after the server closed: its last bytes still count),
    // checking done() and the deadline between messages.
    bool message_done = false;
    while (parse_step(message_done)) {
      if (!message_done) continue;
      if (done()) return true;
      if (Clock::now() >= deadline) return false;
    }
    if (!connected()) return done();
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return done();
    read_some(static_cast<int>(left));
  }
}

bool H264RfbClient::wait_for_updates(std::uint64_t count, std::chrono::milliseconds timeout) {
  const std::uint64_t target = updates_ + count;
  return pump_until([&] { return updates_ >= target; }, timeout);
}

FrameView H264RfbClient::frame() const { return FrameView{pixels_.data(), width_, height_, 0}; }

void H264RfbClient::send_key(std::uint32_t keysym, bool down) {
  std::vector<std::uint8_t> message{4, static_cast<std::uint8_t>(down ? 1 : 0), 0, 0};
  put32(message, keysym);
  send_bytes(message);
}

void H264RfbClient::send_pointer(int x, int y, int buttons) {
  std::vector<std::uint8_t> message{5, static_cast<std::uint8_t>(buttons)};
  put_u16_clamped(message, x);
  put_u16_clamped(message, y);
  send_bytes(message);
}

bool H264RfbClient::send_raw(const std::vector<std::uint8_t>& bytes) { return send_bytes(bytes); }

void H264RfbClient::disable_continuous() { send_bytes(enable_continuous_message(false, width_, height_)); }

void H264RfbClient::request_update(bool incremental) {
  if (send_bytes(update_request_message(incremental, width_, height_))) ++update_requests_sent_;
}

// ---- Parser side: never touches the socket except to send answers ----

bool H264RfbClient::parse_step(bool& message_done) {
  message_done = false;
  // Inside a FramebufferUpdate: one rectangle at a time.
  if (rects_left_ > 0) {
    if (!parse_rect()) return false;
    if (--rects_left_ == 0) {
      finish_update();
      message_done = true;
    }
    return true;
  }
  if (buffered() < 1) return false;
  const std::uint8_t* p = in_data();
  const std::size_t have = buffered();
  switch (p[0]) {
    case 0: {  // FramebufferUpdate: U8 padding, U16 number of rectangles
      if (have < 4) return false;
      rects_left_ = be16(p + 2);
      consume(4);
      if (rects_left_ == 0) {
        finish_update();
        message_done = true;
      }
      return true;
    }
    case 1: {  // SetColourMapEntries: U8 padding, U16 first colour, U16 count, count x 6 bytes
      if (have < 6) return false;
      const std::size_t size = 6 + 6 * std::size_t{be16(p + 4)};
      if (have < size) return false;
      consume(size);
      break;
    }
    case 2:  // Bell
      consume(1);
      break;
    case 3: {  // ServerCutText: 3 padding, U32 length, text
      if (have < 8) return false;
      const std::uint32_t length = be32(p + 4);
      if (length > kMaxCutText) protocol_error("ServerCutText of " + std::to_string(length) + " bytes");
      if (have < 8 + std::size_t{length}) return false;
      consume(8 + std::size_t{length});
      break;
    }
    case 150:  // EndOfContinuousUpdates
      consume(1);
      handle_end_of_continuous();
      break;
    case 248: {  // ServerFence: 3 padding, U32 flags, U8 length, payload
      if (have < 9) return false;
      const std::size_t length = p[8];
      if (have < 9 + length) return false;
      const std::vector<std::uint8_t> payload(p + 9, p + 9 + length);
      const std::uint32_t flags = be32(p + 4);
      consume(9 + length);
      handle_fence(flags, payload.data(), payload.size());
      break;
    }
    default:
      protocol_error("unknown server message type " + std::to_string(p[0]));
  }
  message_done = true;
  return true;
}

bool H264RfbClient::parse_rect() {
  if (buffered() < 12) return false;
  const std::uint8_t* p = in_data();
  const int x = static_cast<int>(be16(p));
  const int y = static_cast<int>(be16(p + 2));
  const int w = static_cast<int>(be16(p + 4));
  const int h = static_cast<int>(be16(p + 6));
  const auto encoding = static_cast<std::int32_t>(be32(p + 8));
  if (encoding == kEncodingTight) {
    protocol_error("a Tight rectangle " + rect_text(x, y, w, h) +
                   ": this client lists Tight only with offer_tight and cannot decode it");
  }
  if (encoding != kEncodingRaw && encoding != kEncodingH264) {
    protocol_error("a rectangle " + rect_text(x, y, w, h) + " in encoding " + std::to_string(encoding) +
                   ", which this client did not list");
  }
  if (x + w > width_ || y + h > height_) protocol_error("a rectangle " + rect_text(x, y, w, h) + " outside the screen");

  if (encoding == kEncodingRaw) {
    const std::size_t size = 12 + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4U;
    if (buffered() < size) return false;
    draw_raw(x, y, w, h, p + 12);
    ++raw_rects_;
    consume(size);
    return true;
  }

  // H.264: U32 length, U32 flags, then length bytes of Annex B.
  if (buffered() < 20) return false;
  const std::uint32_t length = be32(p + 12);
  const std::uint32_t flags = be32(p + 16);
  if (length > kMaxH264Payload) protocol_error("an H.264 rectangle of " + std::to_string(length) + " bytes");
  if (buffered() < 20 + std::size_t{length}) return false;
  const Canvas canvas{pixels_.data(), width_, height_};
  const DecodeTally tally = decoders_->decode(RectKey{x, y, w, h}, flags, p + 20, length, canvas);
  h264_pictures_ += tally.pictures;
  idr_pictures_ += tally.idrs;
  decode_errors_ += tally.errors;
  if (!tally.last_error.empty()) last_error_ = tally.last_error;
  h264_bytes_ += length;
  consume(20 + std::size_t{length});
  return true;
}

void H264RfbClient::draw_raw(int x, int y, int w, int h, const std::uint8_t* data) {
  // One 32-bit pixel in the server's format: shifts and maxima from ServerInit, scaled to 0..255.
  const auto channel = [](std::uint32_t pixel, int shift, std::uint32_t max) {
    const std::uint32_t v = (pixel >> shift) & max;
    return static_cast<std::uint8_t>(max == 255 ? v : v * 255U / max);
  };
  for (int row = 0; row < h; ++row) {
    const std::uint8_t* in = data + static_cast<std::size_t>(row) * static_cast<std::size_t>(w) * 4U;
    std::uint8_t* out = pixels_.data() + (static_cast<std::size_t>(y + row) * static_cast<std::size_t>(width_) +
                                          static_cast<std::size_t>(x)) * 4U;
    for (int col = 0; col < w; ++col, in += 4, out += 4) {
      const std::uint32_t pixel = big_endian_ ? be32(in)
                                              : (std::uint32_t{in[3]} << 24) | (std::uint32_t{in[2]} << 16) |
                                                    (std::uint32_t{in[1]} << 8) | in[0];
      out[0] = channel(pixel, red_shift_, red_max_);
      out[1] = channel(pixel, green_shift_, green_max_);
      out[2] = channel(pixel, blue_shift_, blue_max_);
      out[3] = 255;
    }
  }
}

void H264RfbClient::handle_fence(std::uint32_t flags, const std::uint8_t* payload, std::size_t length) {
  // A server fence must be a request (noVNC fails on anything else) with at most 64 bytes.
  if ((flags & kFenceRequest) == 0 || length > kMaxFencePayload) {
    ++bad_fences_;
    last_error_ = "server fence with flags " + std::to_string(flags) + " and " + std::to_string(length) +
                  " payload bytes";
    return;
  }
  // Answer in order: Request and the unknown bits (SyncNext among them) cleared, payload echoed.
  std::vector<std::uint8_t> answer{248, 0, 0, 0};
  put32(answer, flags & (kFenceBlockBefore | kFenceBlockAfter));
  answer.push_back(static_cast<std::uint8_t>(length));
  answer.insert(answer.end(), payload, payload + length);
  if (send_bytes(answer)) ++fences_answered_;
}

void H264RfbClient::handle_end_of_continuous() {
  ++end_of_continuous_;
  if (options_.continuous_updates && end_of_continuous_ == 1) {
    // The first one says the server does them: turn them on for the whole screen, stop requesting.
    send_bytes(enable_continuous_message(true, width_, height_));
    continuous_ = true;
  } else if (continuous_) {
    // A later one ends them (asked for or not): back to requests.
    continuous_ = false;
    request_update(true);
  }
}

void H264RfbClient::finish_update() {
  ++updates_;
  last_update_time_ = Clock::now();
  if (!continuous_) request_update(true);
}

}  // namespace rfbsim::test
