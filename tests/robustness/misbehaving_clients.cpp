// SPDX-License-Identifier: GPL-2.0-or-later
// Misbehaving clients over raw loopback sockets.
#include "misbehaving_clients.hpp"

#include <random>

namespace rfbsim::test {

using namespace std::chrono_literals;

std::string random_bytes(std::size_t n, std::uint32_t seed) {
  std::mt19937 generator(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::string bytes(n, '\0');
  for (auto& b : bytes) b = static_cast<char>(byte(generator));
  return bytes;
}

bool server_closes_after(int port, std::string_view bytes, std::chrono::milliseconds timeout) {
  RawSocket socket(port);
  if (!socket.send_all(bytes)) return true;  // already closed on us while sending
  bool closed = false;
  socket.read_until_closed(timeout, &closed);
  return closed;
}

RfbServerInit raw_rfb_handshake(RawSocket& socket) {
  const ReadExact read = [&socket](std::size_t n, std::vector<std::uint8_t>& out) {
    return socket.read_exact(n, out, 5s);
  };
  const WriteAll write = [&socket](const std::vector<std::uint8_t>& bytes) { return socket.send_all(bytes); };
  return rfb_client_handshake(read, write);
}

bool vanish_mid_update(int port, int width, int height, int requests, std::size_t read_bytes) {
  RawSocket socket(port, 16 * 1024);
  raw_rfb_handshake(socket);
  // Raw encoding (0) only: every update is width * height * 4 bytes, far more than the buffers hold.
  socket.send_all(rfb_set_encodings({0}));
  for (int i = 0; i < requests; ++i) socket.send_all(rfb_update_request(false, 0, 0, width, height));
  std::vector<std::uint8_t> first;
  const bool started = socket.read_exact(read_bytes, first, 10s) && first.at(0) == 0;
  socket.reset();
  return started;
}

std::string raw_websocket_upgrade(RawSocket& socket, int port) {
  if (!socket.send_all(ws_upgrade_request(port, "/websockify"))) return {};
  return socket.read_until("\r\n\r\n", 5s);
}

std::vector<std::uint8_t> ws_header_claiming(std::uint64_t length, std::uint32_t mask) {
  std::vector<std::uint8_t> header{0x82, 0x80 | 127};
  for (int shift = 56; shift >= 0; shift -= 8) header.push_back(static_cast<std::uint8_t>(length >> shift));
  for (int shift = 24; shift >= 0; shift -= 8) header.push_back(static_cast<std::uint8_t>(mask >> shift));
  return header;
}

std::vector<std::uint8_t> ws_mask(const std::vector<std::uint8_t>& payload, std::uint32_t mask) {
  std::vector<std::uint8_t> out(payload.size());
  for (std::size_t i = 0; i < payload.size(); ++i) {
    out[i] = static_cast<std::uint8_t>(payload[i] ^ static_cast<std::uint8_t>(mask >> (24 - 8 * (i % 4))));
  }
  return out;
}

}  // namespace rfbsim::test
