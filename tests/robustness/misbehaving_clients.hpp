// SPDX-License-Identifier: GPL-2.0-or-later
// Misbehaving clients shared by the in-process and the sim_rfb process robustness tests. Each one
// connects on its own raw socket, does one bad thing, and reports what it could observe.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "raw_socket.hpp"
#include "rfb_wire.hpp"

namespace rfbsim::test {

/// `n` bytes from a fixed-seed generator (the same bytes on every run).
std::string random_bytes(std::size_t n, std::uint32_t seed);

/// Connects, sends `bytes` at once and waits up to `timeout` for the server to close the connection.
/// Returns whether it did (EOF or reset).
bool server_closes_after(int port, std::string_view bytes, std::chrono::milliseconds timeout);

/// Plays the client side of the RFB handshake by hand on `socket` (5 s per read).
RfbServerInit raw_rfb_handshake(RawSocket& socket);

/// A client that vanishes mid-update: completes the handshake, asks `requests` times for a Raw update
/// of the whole `width` x `height` frame with a small receive buffer, reads `read_bytes` of the answer
/// and then resets the connection (SO_LINGER 0) without reading the rest. Returns whether those first
/// bytes arrived and began a FramebufferUpdate.
bool vanish_mid_update(int port, int width, int height, int requests, std::size_t read_bytes);

/// Sends a WebSocket upgrade for /websockify by hand and returns the server's response head
/// ("" when the server closed the connection or stayed silent).
std::string raw_websocket_upgrade(RawSocket& socket, int port);

/// The header of a masked binary frame that claims `length` payload bytes in the 64-bit length form.
std::vector<std::uint8_t> ws_header_claiming(std::uint64_t length, std::uint32_t mask);

/// Masks `payload` with `mask` as a client frame's payload starting at payload offset 0.
std::vector<std::uint8_t> ws_mask(const std::vector<std::uint8_t>& payload, std::uint32_t mask);

}  // namespace rfbsim::test
