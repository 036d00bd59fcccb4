// SPDX-License-Identifier: GPL-2.0-or-later
// RFB 3.8 and WebSocket wire pieces written by hand, for tests that play a client byte by byte:
// message builders, the client side of the RFB handshake over any byte stream, and a reader for one
// FramebufferUpdate in Raw encoding. No sockets here: the caller passes the read and write functions.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace rfbsim::test {

/// Reads exactly n bytes into out; false when the stream ends or times out first.
using ReadExact = std::function<bool(std::size_t n, std::vector<std::uint8_t>& out)>;
/// Writes all bytes; false on failure.
using WriteAll = std::function<bool(const std::vector<std::uint8_t>& bytes)>;

/// What the server announced in its ServerInit message.
struct RfbServerInit {
  int width = 0;
  int height = 0;
  int bits_per_pixel = 0;
  int depth = 0;
  bool true_colour = false;
  std::string name;
};

/// Plays the client side of the RFB 3.8 handshake: version, security type None, SecurityResult,
/// ClientInit (shared), ServerInit. Throws std::runtime_error naming the step that went wrong.
RfbServerInit rfb_client_handshake(const ReadExact& read, const WriteAll& write);

/// SetEncodings (message type 2) with the given encoding numbers.
std::vector<std::uint8_t> rfb_set_encodings(const std::vector<std::int32_t>& encodings);
/// FramebufferUpdateRequest (message type 3).
std::vector<std::uint8_t> rfb_update_request(bool incremental, int x, int y, int w, int h);
/// The 8-byte header of a ClientCutText (message type 6) claiming `length` bytes of text.
std::vector<std::uint8_t> rfb_client_cut_text_header(std::uint32_t length);

/// One rectangle of a FramebufferUpdate as received.
struct RfbRect {
  int x = 0;
  int y = 0;
  int w = 0;
  int h = 0;
  std::int32_t encoding = 0;
  std::vector<std::uint8_t> pixels;  ///< Raw encoding only: w * h * bytes_per_pixel bytes
};

/// Reads one server message that must be a FramebufferUpdate (type 0) whose rectangles are all Raw;
/// throws std::runtime_error otherwise.
std::vector<RfbRect> rfb_read_raw_update(const ReadExact& read, int bytes_per_pixel);

/// The opening handshake of a WebSocket client, asking for `path` with the binary subprotocol.
std::string ws_upgrade_request(int port, std::string_view path);

/// A masked client frame: FIN set, `opcode`, a length field that tells the truth, the given mask.
std::vector<std::uint8_t> ws_masked_frame(std::uint8_t opcode, const std::vector<std::uint8_t>& payload,
                                          std::uint32_t mask = 0x12345678U);

}  // namespace rfbsim::test
