// SPDX-License-Identifier: GPL-2.0-or-later
// RfbInputFilter: makes one RFB connection view-only by dropping the client's input messages. Pure: no I/O.
//
// A researcher watching a session must neither steer it nor be taken for the participant. The watch relay
// therefore frames the client-to-server byte stream message by message and passes everything except key,
// pointer and clipboard input. A stream it cannot frame fails the filter (and the relay closes that one
// connection): passing bytes it does not understand could smuggle input through.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace rfbsim::manager {

class RfbInputFilter {
 public:
  /// Largest ClientCutText accepted, bytes (its text is dropped anyway; a larger one fails the filter).
  static constexpr std::size_t kMaxCutText = std::size_t{1} << 20;
  /// Largest Fence payload, bytes (the RFB extension's own limit).
  static constexpr std::size_t kMaxFencePayload = 64;

  /// Takes the next bytes the client sent (any split: a message may span calls, a call may hold many) and
  /// returns those to pass on to the server, in order. The handshake passes unchanged, except that
  /// ClientInit always asks for a shared session (a watcher must never make the server drop the
  /// participant). KeyEvent, PointerEvent, ClientCutText and QEMU extended key events are dropped whole.
  /// After a failure, returns what preceded it in this chunk and nothing from then on.
  std::string forward(std::string_view chunk);

  /// Whether the stream could not be framed; the connection must then be closed.
  [[nodiscard]] bool failed() const { return !failure_.empty(); }
  /// Why, in a few words (at most 123 bytes, so it fits a WebSocket close reason); "" while not failed.
  [[nodiscard]] const std::string& failure() const { return failure_; }
  /// Input messages dropped so far.
  [[nodiscard]] std::uint64_t dropped_messages() const { return dropped_; }

 private:
  enum class Phase { kVersion, kSecurityType, kVncAuthResponse, kClientInit, kMessages };

  /// What the bytes in head_ tell about the unit they start.
  struct Framing {
    bool complete = false;  ///< head_ holds enough to know the unit's size (else: read one more byte)
    std::size_t size = 0;   ///< the whole unit, head_ included
    bool pass = true;       ///< forward it (else drop it)
  };

  Framing frame_head();
  Framing frame_message();
  Framing fail(std::string reason);

  Phase phase_ = Phase::kVersion;
  bool version_3_3_ = false;  ///< the client chose 3.3 (or older): no security type byte from it
  std::string head_;          ///< the start of the current unit, until its size is known
  std::size_t rest_ = 0;      ///< bytes of the current unit still to come after head_
  bool rest_passes_ = true;   ///< whether those bytes are forwarded
  std::string failure_;
  std::uint64_t dropped_ = 0;
};

}  // namespace rfbsim::manager
