// SPDX-License-Identifier: GPL-2.0-or-later
// The RFB extensions libvncserver lacks: ContinuousUpdates (pseudo-encoding -313, client message 150,
// server message EndOfContinuousUpdates 150), Fence (pseudo-encoding -312, message 248 both ways) and the
// offer of the open H.264 rectangle (encoding 50), as rfbproto describes them.
//
// Two layers. The pure one (message builders and parsers, StreamingState) knows no sockets and is unit
// tested byte for byte. The glue registers one rfbProtocolExtension with libvncserver: SetEncodings
// reports what each client offers, unknown client messages 150 and 248 reach handle_message, and server
// messages are written on the network thread under the client's sendMutex.
//
// What noVNC (1.3..1.7) tolerates shapes the rules: it enables ContinuousUpdates on the FIRST
// EndOfContinuousUpdates only and stops on any later unasked one, fails on a server fence without the
// Request bit, and mishandles payloads over 64 bytes. So the server announces once (a ServerFence with
// Request, then one EndOfContinuousUpdates), sends EndOfContinuousUpdates again only when the client asks
// to disable, and keeps its own fence payloads at one byte.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "rfbsim/tile_damage.hpp"

struct _rfbClientRec;

namespace rfbsim::detail {

constexpr int kPseudoEncodingFence = -312;
constexpr int kPseudoEncodingContinuousUpdates = -313;
constexpr int kEncodingH264 = 50;
constexpr std::uint8_t kMessageContinuousUpdates = 150;  // EnableContinuousUpdates / EndOfContinuousUpdates
constexpr std::uint8_t kMessageFence = 248;               // ClientFence / ServerFence
constexpr std::size_t kMaxFencePayload = 64;

/// Fence flags (rfbproto): what the receiver must do around the fence, and whether it asks for an answer.
enum FenceFlag : std::uint32_t {
  kFenceBlockBefore = 1U << 0,
  kFenceBlockAfter = 1U << 1,
  kFenceSyncNext = 1U << 2,
  kFenceRequest = 1U << 31,
};

/// H.264 rectangle flags (the open H.264 encoding 50).
enum H264Flag : std::uint32_t { kH264ResetContext = 1U << 0, kH264ResetAllContexts = 1U << 1 };

/// The bytes of a Fence message (248, 3 padding, U32 flags, U8 length, payload). Payload <= 64 bytes.
std::vector<std::uint8_t> fence_message(std::uint32_t flags, std::span<const std::uint8_t> payload);
/// The one byte of EndOfContinuousUpdates.
std::vector<std::uint8_t> end_of_continuous_updates_message();
/// The flags of the answer to a fence request: Request cleared, and every flag we do not implement
/// (SyncNext, unknown bits) cleared too, as rfbproto asks of a responder.
std::uint32_t fence_answer_flags(std::uint32_t request_flags);
/// A FramebufferUpdate of one H.264 rectangle covering (0, 0, width, height): the header that goes
/// before `data_length` bytes of Annex B data.
std::vector<std::uint8_t> h264_update_header(int width, int height, std::uint32_t data_length, std::uint32_t flags);

/// The fixed part of a Fence after its type byte: 3 padding, U32 flags, U8 payload length.
struct FenceHead {
  std::uint32_t flags = 0;
  std::uint8_t payload_length = 0;
};
/// Parses the 8 bytes after a fence's type byte. nullopt when the payload would exceed 64 bytes.
std::optional<FenceHead> parse_fence_head(std::span<const std::uint8_t, 8> bytes);

/// EnableContinuousUpdates after its type byte: U8 enable, U16 x, y, w, h.
struct ContinuousUpdatesRequest {
  bool enable = false;
  PixelRect area{};
};
/// Parses the 9 bytes after the type byte; nullopt when the area is empty or leaves the framebuffer
/// (`width` x `height`), which rfbproto makes a protocol error.
std::optional<ContinuousUpdatesRequest> parse_continuous_updates(std::span<const std::uint8_t, 9> bytes, int width,
                                                                  int height);

/// What one client negotiated, and the server's side of that negotiation. Network thread only.
struct StreamingState {
  bool offers_fence = false;         ///< listed -312 in SetEncodings
  bool offers_continuous = false;    ///< listed -313
  bool offers_h264 = false;          ///< listed 50
  bool fence_announced = false;      ///< our first ServerFence(Request) went out
  bool announced = false;            ///< ... and then EndOfContinuousUpdates: the client may enable them
  bool continuous = false;           ///< ContinuousUpdates on: updates are pushed, not requested
  PixelRect continuous_area{};       ///< the area pushed while `continuous`
  bool full_update_requested = false;  ///< a non-incremental update request arrived since the last update
  std::uint64_t update_requests = 0;  ///< FramebufferUpdateRequests received
  std::uint64_t unasked_fence_answers = 0;  ///< fence answers that matched no ping of ours (ignored)
  std::uint64_t position = 0;        ///< RFB bytes written to this client so far (the stream position)
};

/// Registers the extension with libvncserver (once per process; later calls do nothing).
void register_streaming_extension();

/// Writes a fence to the client under its sendMutex. False when the write failed (the client is closed).
bool write_fence(_rfbClientRec* client, std::uint32_t flags, std::span<const std::uint8_t> payload);
/// Writes EndOfContinuousUpdates under the client's sendMutex.
bool write_end_of_continuous_updates(_rfbClientRec* client);
/// Writes raw bytes (a whole server message) under the client's sendMutex.
bool write_message(_rfbClientRec* client, std::span<const std::uint8_t> bytes);

}  // namespace rfbsim::detail
