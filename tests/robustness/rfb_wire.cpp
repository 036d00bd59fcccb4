// SPDX-License-Identifier: GPL-2.0-or-later
// Hand-written RFB 3.8 client messages and handshake; WebSocket client framing.
#include "rfb_wire.hpp"

#include <stdexcept>

namespace rfbsim::test {

namespace {

void put16(std::vector<std::uint8_t>& out, std::uint32_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  put16(out, v >> 16);
  put16(out, v & 0xffffU);
}

std::uint32_t get16(const std::vector<std::uint8_t>& in, std::size_t at) {
  return (std::uint32_t{in.at(at)} << 8) | std::uint32_t{in.at(at + 1)};
}

std::uint32_t get32(const std::vector<std::uint8_t>& in, std::size_t at) {
  return (get16(in, at) << 16) | get16(in, at + 2);
}

std::vector<std::uint8_t> need(const ReadExact& read, std::size_t n, const char* what) {
  std::vector<std::uint8_t> bytes;
  if (!read(n, bytes)) {
    throw std::runtime_error(std::string("RFB stream ended while reading ") + what + " (got " +
                             std::to_string(bytes.size()) + " of " + std::to_string(n) + " bytes)");
  }
  return bytes;
}

void send(const WriteAll& write, const std::vector<std::uint8_t>& bytes, const char* what) {
  if (!write(bytes)) throw std::runtime_error(std::string("could not send ") + what);
}

}  // namespace

RfbServerInit rfb_client_handshake(const ReadExact& read, const WriteAll& write) {
  // ProtocolVersion: the server speaks first; answer with the same version.
  const auto version = need(read, 12, "the protocol version");
  const std::string version_text(version.begin(), version.end());
  if (version_text != "RFB 003.008\n") throw std::runtime_error("unexpected server version '" + version_text + "'");
  send(write, version, "the protocol version");

  // Security: a count then the types; 0 means a failure reason follows.
  const auto count = need(read, 1, "the number of security types").at(0);
  if (count == 0) {
    const auto length = get32(need(read, 4, "the failure reason length"), 0);
    const auto reason = need(read, length, "the failure reason");
    throw std::runtime_error("server refused: " + std::string(reason.begin(), reason.end()));
  }
  const auto types = need(read, count, "the security types");
  bool none_offered = false;
  for (const auto type : types) none_offered = none_offered || type == 1;
  if (!none_offered) throw std::runtime_error("server does not offer security type None");
  send(write, {1}, "the security type");
  if (get32(need(read, 4, "the security result"), 0) != 0) throw std::runtime_error("security result is not OK");

  // ClientInit (shared) and ServerInit.
  send(write, {1}, "ClientInit");
  const auto init = need(read, 24, "ServerInit");
  RfbServerInit result;
  result.width = static_cast<int>(get16(init, 0));
  result.height = static_cast<int>(get16(init, 2));
  result.bits_per_pixel = init.at(4);
  result.depth = init.at(5);
  result.true_colour = init.at(7) != 0;
  const auto name_length = get32(init, 20);
  if (name_length > 4096) throw std::runtime_error("absurd desktop name length " + std::to_string(name_length));
  const auto name = need(read, name_length, "the desktop name");
  result.name.assign(name.begin(), name.end());
  return result;
}

std::vector<std::uint8_t> rfb_set_encodings(const std::vector<std::int32_t>& encodings) {
  std::vector<std::uint8_t> out{2, 0};
  put16(out, static_cast<std::uint32_t>(encodings.size()));
  for (const auto encoding : encodings) put32(out, static_cast<std::uint32_t>(encoding));
  return out;
}

std::vector<std::uint8_t> rfb_update_request(bool incremental, int x, int y, int w, int h) {
  std::vector<std::uint8_t> out{3, static_cast<std::uint8_t>(incremental ? 1 : 0)};
  for (const int v : {x, y, w, h}) put16(out, static_cast<std::uint32_t>(v));
  return out;
}

std::vector<std::uint8_t> rfb_client_cut_text_header(std::uint32_t length) {
  std::vector<std::uint8_t> out{6, 0, 0, 0};
  put32(out, length);
  return out;
}

std::vector<RfbRect> rfb_read_raw_update(const ReadExact& read, int bytes_per_pixel) {
  const auto header = need(read, 4, "a server message header");
  if (header.at(0) != 0) {
    throw std::runtime_error("expected a FramebufferUpdate (type 0), got message type " + std::to_string(header[0]));
  }
  const auto count = get16(header, 2);
  std::vector<RfbRect> rects;
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto rect_header = need(read, 12, "a rectangle header");
    RfbRect rect;
    rect.x = static_cast<int>(get16(rect_header, 0));
    rect.y = static_cast<int>(get16(rect_header, 2));
    rect.w = static_cast<int>(get16(rect_header, 4));
    rect.h = static_cast<int>(get16(rect_header, 6));
    rect.encoding = static_cast<std::int32_t>(get32(rect_header, 8));
    if (rect.encoding != 0) {
      throw std::runtime_error("expected Raw rectangles, got encoding " + std::to_string(rect.encoding));
    }
    const auto bytes = static_cast<std::size_t>(rect.w) * static_cast<std::size_t>(rect.h) *
                       static_cast<std::size_t>(bytes_per_pixel);
    rect.pixels = need(read, bytes, "Raw pixels");
    rects.push_back(std::move(rect));
  }
  return rects;
}

std::string ws_upgrade_request(int port, std::string_view path) {
  std::string request = "GET " + std::string(path) + " HTTP/1.1\r\n";
  request += "Host: 127.0.0.1:" + std::to_string(port) + "\r\n";
  request += "Origin: http://127.0.0.1:" + std::to_string(port) + "\r\n";
  request += "Upgrade: websocket\r\n";
  request += "Connection: Upgrade\r\n";
  request += "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n";
  request += "Sec-WebSocket-Version: 13\r\n";
  request += "Sec-WebSocket-Protocol: binary\r\n";
  request += "\r\n";
  return request;
}

std::vector<std::uint8_t> ws_masked_frame(std::uint8_t opcode, const std::vector<std::uint8_t>& payload,
                                          std::uint32_t mask) {
  std::vector<std::uint8_t> out{static_cast<std::uint8_t>(0x80U | (opcode & 0x0fU))};
  const std::size_t n = payload.size();
  if (n < 126) {
    out.push_back(static_cast<std::uint8_t>(0x80U | n));
  } else if (n <= 0xffff) {
    out.push_back(0x80U | 126U);
    put16(out, static_cast<std::uint32_t>(n));
  } else {
    out.push_back(0x80U | 127U);
    put32(out, static_cast<std::uint32_t>(static_cast<std::uint64_t>(n) >> 32));
    put32(out, static_cast<std::uint32_t>(n));
  }
  put32(out, mask);
  const std::uint8_t key[4] = {static_cast<std::uint8_t>(mask >> 24), static_cast<std::uint8_t>(mask >> 16),
                               static_cast<std::uint8_t>(mask >> 8), static_cast<std::uint8_t>(mask)};
  for (std::size_t i = 0; i < n; ++i) out.push_back(static_cast<std::uint8_t>(payload[i] ^ key[i % 4]));
  return out;
}

}  // namespace rfbsim::test
