// SPDX-License-Identifier: GPL-2.0-or-later
// H264RfbClient: a hand-written RFB 3.8 client for tests and benchmarks that receives the open H.264
// rectangle (encoding 50) the way noVNC does: one decoder per rectangle, Fence answered, ContinuousUpdates
// enabled at the server's first EndOfContinuousUpdates. Plain TCP, security None, the server's own 32-bit
// pixel format. Pictures are decoded with libavcodec's h264 decoder into an RGBA framebuffer.
//
// Errors, in three kinds:
//   - the connection or the handshake fails: the constructor throws std::runtime_error naming the step;
//   - the server sends bytes this client cannot follow (an unknown message type or encoding, a Tight
//     rectangle, a rectangle outside the screen): pump_until() closes the connection and throws
//     std::runtime_error saying what came; the stream cannot be resynchronised after that;
//   - an H.264 picture does not decode: counted in decode_errors(), never thrown; that rectangle's decoder
//     is reset and skips pictures (each counted as an error) until the next IDR, which recovers it.
// Not thread-safe: one thread calls everything.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rfbsim/frame.hpp"

namespace rfbsim::test {

/// How the client talks to the server; the defaults are what noVNC >= 1.6 does with H.264 available.
struct H264RfbClientOptions {
  /// Lists ContinuousUpdates (-313) and turns them on at the first EndOfContinuousUpdates; false: lists
  /// it not, and asks for an incremental update after every update.
  bool continuous_updates = true;
  /// Lists Fence (-312) (servers such as TigerVNC refuse ContinuousUpdates without it). Server fences
  /// are answered either way.
  bool fence = true;
  /// Also lists Tight (7) between H.264 and Raw. This client cannot decode Tight: a Tight rectangle
  /// makes pump_until() throw. For testing that a server never falls back to Tight when H.264 is offered.
  bool offer_tight = false;
  /// Time allowed for the TCP connection and the whole handshake, in milliseconds.
  std::chrono::milliseconds handshake_timeout{10000};
};

class H264RfbClient {
 public:
  /// Connects over TCP to host:port (a name or a numeric address), completes the RFB 3.8 handshake, sends
  /// SetEncodings (50, [7,] 0, [-312,] [-313]) and a non-incremental update request for the whole screen.
  /// Throws std::runtime_error naming the failed step (connect, ProtocolVersion, security, SecurityResult,
  /// ServerInit, ...) or when the server's pixel format is not 32 bits per pixel true colour.
  H264RfbClient(const std::string& host, int port, const H264RfbClientOptions& options = {});
  ~H264RfbClient();
  H264RfbClient(const H264RfbClient&) = delete;
  H264RfbClient& operator=(const H264RfbClient&) = delete;

  /// Reads and handles server messages until `done()` holds, the connection ends, or `timeout` passes;
  /// `done()` is checked between whole messages, so frame() never shows half an update when it holds.
  /// Returns whether `done()` held. Throws std::runtime_error on bytes it cannot parse (see above).
  bool pump_until(const std::function<bool()>& done, std::chrono::milliseconds timeout);
  /// Waits until `count` more complete framebuffer updates have arrived (and been decoded).
  bool wait_for_updates(std::uint64_t count, std::chrono::milliseconds timeout);

  /// Complete framebuffer updates received (and decoded) so far.
  [[nodiscard]] std::uint64_t updates() const { return updates_; }
  /// Whether the connection still works (false after the server closed it, a read or write error, or a
  /// protocol error).
  [[nodiscard]] bool connected() const { return fd_ >= 0; }
  /// Framebuffer width and height in pixels, from ServerInit.
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  /// The decoded picture as RGBA (alpha 255 where drawn, 0 where nothing was drawn yet), top row first.
  /// Valid until the next pump_until() or the client's destruction.
  [[nodiscard]] FrameView frame() const;
  /// The desktop name from ServerInit.
  [[nodiscard]] const std::string& desktop_name() const { return desktop_name_; }

  /// KeyEvent (X11 keysym). Write failures mark the client disconnected.
  void send_key(std::uint32_t keysym, bool down);
  /// PointerEvent at (x, y) in framebuffer pixels, clamped to 0..65535; `buttons` bit 0 = left.
  void send_pointer(int x, int y, int buttons);
  /// Sends raw bytes as they are (a whole client message, or a malformed one). False on failure.
  bool send_raw(const std::vector<std::uint8_t>& bytes);
  /// Asks the server to stop pushing (EnableContinuousUpdates with enable 0) and goes back to requests
  /// once the server confirms with EndOfContinuousUpdates.
  void disable_continuous();

  /// H.264 pictures decoded and drawn.
  [[nodiscard]] std::uint64_t h264_pictures() const { return h264_pictures_; }
  /// Access units with an IDR slice received (decodable or not).
  [[nodiscard]] std::uint64_t idr_pictures() const { return idr_pictures_; }
  /// H.264 pictures that failed: refused by the decoder, no picture out, flagged corrupt, skipped while
  /// waiting for an IDR, or decoded at a size other than their rectangle's.
  [[nodiscard]] std::uint64_t decode_errors() const { return decode_errors_; }
  /// Bytes of H.264 payload received (the `length` bytes of each encoding-50 rectangle).
  [[nodiscard]] std::uint64_t h264_bytes() const { return h264_bytes_; }
  /// Raw (encoding 0) rectangles received.
  [[nodiscard]] std::uint64_t raw_rects() const { return raw_rects_; }
  /// Bytes read from the socket since the connection opened, handshake included.
  [[nodiscard]] std::uint64_t bytes_received() const { return bytes_received_; }
  /// FramebufferUpdateRequests sent (the first, non-incremental one included).
  [[nodiscard]] std::uint64_t update_requests_sent() const { return update_requests_sent_; }
  /// Server fences answered (each had the Request bit and a payload of at most 64 bytes).
  [[nodiscard]] int fences_answered() const { return fences_answered_; }
  /// Server fences without the Request bit or with a payload over 64 bytes (fatal to noVNC); not answered.
  [[nodiscard]] int bad_fences() const { return bad_fences_; }
  /// Whether ContinuousUpdates are on (enabled by this client and not ended by the server since).
  [[nodiscard]] bool continuous() const { return continuous_; }
  /// EndOfContinuousUpdates messages received.
  [[nodiscard]] int end_of_continuous_updates() const { return end_of_continuous_; }
  /// steady_clock time at which the latest complete update finished decoding (epoch before the first).
  [[nodiscard]] std::chrono::steady_clock::time_point last_update_time() const { return last_update_time_; }
  /// Why the connection ended or the latest decode error, in words; "" when none yet.
  [[nodiscard]] const std::string& last_error() const { return last_error_; }

 private:
  struct Decoders;  // libavcodec decoders keyed by rectangle, and the swscale converter

  // Socket side: bytes in and out.
  void read_some(int timeout_ms);
  const std::uint8_t* read_exact(std::size_t n, std::chrono::steady_clock::time_point deadline,
                                 const char* step);
  bool send_bytes(const std::vector<std::uint8_t>& bytes);
  void close_connection(const std::string& why);
  [[noreturn]] void protocol_error(const std::string& what);

  // Parser side: one step over the buffered bytes; false when more bytes are needed.
  bool parse_step(bool& message_done);
  bool parse_rect();
  void handle_fence(std::uint32_t flags, const std::uint8_t* payload, std::size_t length);
  void handle_end_of_continuous();
  void draw_raw(int x, int y, int w, int h, const std::uint8_t* data);
  void finish_update();
  void request_update(bool incremental);
  [[nodiscard]] std::size_t buffered() const { return in_end_ - in_begin_; }
  [[nodiscard]] const std::uint8_t* in_data() const { return in_.data() + in_begin_; }
  void consume(std::size_t n) { in_begin_ += n; }

  H264RfbClientOptions options_;
  int fd_ = -1;
  std::vector<std::uint8_t> in_;  // read buffer: bytes [in_begin_, in_end_) are received and not yet parsed
  std::size_t in_begin_ = 0;
  std::size_t in_end_ = 0;
  std::uint32_t rects_left_ = 0;  // rectangles still to come in the FramebufferUpdate being parsed

  int width_ = 0;
  int height_ = 0;
  std::string desktop_name_;
  // The server's pixel format for Raw rectangles (32 bits per pixel, true colour).
  bool big_endian_ = false;
  std::uint32_t red_max_ = 255, green_max_ = 255, blue_max_ = 255;
  int red_shift_ = 0, green_shift_ = 8, blue_shift_ = 16;
  std::vector<std::uint8_t> pixels_;  // RGBA, width_ * height_ * 4
  std::unique_ptr<Decoders> decoders_;

  std::uint64_t updates_ = 0;
  std::uint64_t h264_pictures_ = 0;
  std::uint64_t idr_pictures_ = 0;
  std::uint64_t decode_errors_ = 0;
  std::uint64_t h264_bytes_ = 0;
  std::uint64_t raw_rects_ = 0;
  std::uint64_t bytes_received_ = 0;
  std::uint64_t update_requests_sent_ = 0;
  int fences_answered_ = 0;
  int bad_fences_ = 0;
  bool continuous_ = false;
  int end_of_continuous_ = 0;
  std::chrono::steady_clock::time_point last_update_time_{};
  std::string last_error_;
};

}  // namespace rfbsim::test
