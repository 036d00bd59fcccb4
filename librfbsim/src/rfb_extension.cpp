// SPDX-License-Identifier: GPL-2.0-or-later
// ContinuousUpdates, Fence and the H.264 offer: message bytes, and the libvncserver glue.
#include "rfb_extension.hpp"

#include <rfb/rfb.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>

#include "client_state.hpp"
#include "rfbsim/log.hpp"

namespace rfbsim::detail {

namespace {

void put_u16(std::vector<std::uint8_t>& out, unsigned value) {
  out.push_back(static_cast<std::uint8_t>(value >> 8));
  out.push_back(static_cast<std::uint8_t>(value));
}

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(value >> shift));
}

std::uint16_t get_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }

std::uint32_t get_u32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

ClientState* state_of(rfbClientPtr cl) { return static_cast<ClientState*>(cl->clientData); }

// A peer's bad bytes close that one connection and nothing else; by id only, as addresses stay out of logs.
void drop(rfbClientPtr cl, const char* why) {
  const ClientState* state = state_of(cl);
  rfbsim::log::limited(rfbsim::log::Level::kInfo, "client-dropped", "rfbsim.server", "dropping client %d: %s",
                       state != nullptr ? state->info.id : 0, why);
  rfbCloseClient(cl);
}

// SetEncodings lists each of our encodings: remember what the client offers. Returning TRUE tells
// libvncserver the encoding is handled (it then enables the extension for this client, which routes
// messages 150 and 248 to handle_message).
rfbBool enable_encoding(rfbClientPtr cl, void** /*data*/, int encoding) {
  ClientState* state = state_of(cl);
  if (state == nullptr) return FALSE;
  StreamingState& s = state->streamer.protocol();
  switch (encoding) {
    case kPseudoEncodingFence: s.offers_fence = true; return TRUE;
    case kPseudoEncodingContinuousUpdates: s.offers_continuous = true; return TRUE;
    case kEncodingH264: s.offers_h264 = true; return TRUE;
    default: return FALSE;
  }
}

// EnableContinuousUpdates: only after we announced it, which needs Fence too (TigerVNC's rule; without
// fences there is no congestion control, and pushed updates would flood a slow link).
void handle_continuous_updates(rfbClientPtr cl, ClientState& state) {
  std::uint8_t rest[9];
  if (rfbReadExact(cl, reinterpret_cast<char*>(rest), sizeof rest) <= 0) {
    rfbCloseClient(cl);
    return;
  }
  StreamingState& s = state.streamer.protocol();
  if (!s.announced) {
    drop(cl, "EnableContinuousUpdates without ContinuousUpdates and Fence negotiated");
    return;
  }
  const auto request = parse_continuous_updates(std::span<const std::uint8_t, 9>(rest), cl->screen->width,
                                                cl->screen->height);
  if (!request) {
    drop(cl, "EnableContinuousUpdates with an area outside the framebuffer");
    return;
  }
  if (request->enable) {
    s.continuous = true;
    s.continuous_area = request->area;
    return;
  }
  // Disabling is confirmed with EndOfContinuousUpdates, after which the client requests updates again.
  s.continuous = false;
  if (write_end_of_continuous_updates(cl)) s.position += 1;
}

// A fence from the client: a request gets its answer at once (messages are handled in order, so
// BlockBefore and BlockAfter already hold); an answer is the pong of our oldest ping.
void handle_fence(rfbClientPtr cl, ClientState& state) {
  std::uint8_t head_bytes[8];
  if (rfbReadExact(cl, reinterpret_cast<char*>(head_bytes), sizeof head_bytes) <= 0) {
    rfbCloseClient(cl);
    return;
  }
  const auto head = parse_fence_head(std::span<const std::uint8_t, 8>(head_bytes));
  if (!head) {
    drop(cl, "fence payload over 64 bytes");
    return;
  }
  std::uint8_t payload[255];
  if (head->payload_length > 0 && rfbReadExact(cl, reinterpret_cast<char*>(payload), head->payload_length) <= 0) {
    rfbCloseClient(cl);
    return;
  }
  if ((head->flags & kFenceRequest) != 0) {
    const std::span<const std::uint8_t> echoed(payload, head->payload_length);
    if (write_fence(cl, fence_answer_flags(head->flags), echoed)) state.streamer.protocol().position += 9 + echoed.size();
    return;
  }
  if (!state.streamer.fence_answered(std::chrono::steady_clock::now())) ++state.streamer.protocol().unasked_fence_answers;
}

// Client messages libvncserver does not know reach every extension enabled for the client, with only the
// type byte read. TRUE: ours (handled, or the client was dropped).
rfbBool handle_message(rfbClientPtr cl, void* /*data*/, const rfbClientToServerMsg* message) {
  ClientState* state = state_of(cl);
  if (state == nullptr) return FALSE;
  switch (message->type) {
    case kMessageContinuousUpdates: handle_continuous_updates(cl, *state); return TRUE;
    case kMessageFence:
      if (!state->streamer.protocol().offers_fence) {
        drop(cl, "Fence message without Fence negotiated");
        return TRUE;
      }
      handle_fence(cl, *state);
      return TRUE;
    default: return FALSE;
  }
}

int g_encodings[] = {kPseudoEncodingFence, kPseudoEncodingContinuousUpdates, kEncodingH264, 0};

rfbProtocolExtension g_extension = {
    nullptr,          // newClient: nothing per client here (ClientState holds it)
    nullptr,          // init
    g_encodings,      // pseudoEncodings (50 is a real encoding, but listing it is how we hear of it)
    enable_encoding,  // enablePseudoEncoding
    handle_message,   // handleMessage
    nullptr,          // close (never called by libvncserver 0.9.14)
    nullptr,          // usage
    nullptr,          // processArgument
    nullptr,          // next
};

}  // namespace

std::vector<std::uint8_t> fence_message(std::uint32_t flags, std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> out{kMessageFence, 0, 0, 0};
  put_u32(out, flags);
  const std::size_t length = std::min(payload.size(), kMaxFencePayload);
  out.push_back(static_cast<std::uint8_t>(length));
  out.insert(out.end(), payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(length));
  return out;
}

std::vector<std::uint8_t> end_of_continuous_updates_message() { return {kMessageContinuousUpdates}; }

std::uint32_t fence_answer_flags(std::uint32_t request_flags) {
  return request_flags & (kFenceBlockBefore | kFenceBlockAfter);
}

std::vector<std::uint8_t> h264_update_header(int width, int height, std::uint32_t data_length, std::uint32_t flags) {
  std::vector<std::uint8_t> out{0, 0};  // FramebufferUpdate, padding
  put_u16(out, 1);                      // one rectangle
  put_u16(out, 0);
  put_u16(out, 0);
  put_u16(out, static_cast<unsigned>(width));
  put_u16(out, static_cast<unsigned>(height));
  put_u32(out, static_cast<std::uint32_t>(kEncodingH264));
  put_u32(out, data_length);
  put_u32(out, flags);
  return out;
}

std::optional<FenceHead> parse_fence_head(std::span<const std::uint8_t, 8> bytes) {
  FenceHead head;
  head.flags = get_u32(bytes.data() + 3);
  head.payload_length = bytes[7];
  if (head.payload_length > kMaxFencePayload) return std::nullopt;
  return head;
}

std::optional<ContinuousUpdatesRequest> parse_continuous_updates(std::span<const std::uint8_t, 9> bytes, int width,
                                                                  int height) {
  ContinuousUpdatesRequest request;
  request.enable = bytes[0] != 0;
  request.area = {get_u16(bytes.data() + 1), get_u16(bytes.data() + 3), get_u16(bytes.data() + 5),
                  get_u16(bytes.data() + 7)};
  // A disable carries an area too, which means nothing; only an enable's area must fit.
  if (!request.enable) return request;
  const PixelRect& a = request.area;
  if (a.w <= 0 || a.h <= 0 || a.x + a.w > width || a.y + a.h > height) return std::nullopt;
  return request;
}

void register_streaming_extension() {
  static std::once_flag once;
  std::call_once(once, [] { rfbRegisterProtocolExtension(&g_extension); });
}

bool write_message(rfbClientPtr client, std::span<const std::uint8_t> bytes) {
  if (client->sock == RFB_INVALID_SOCKET) return false;
#ifdef LIBVNCSERVER_SEND_MUTEX
  pthread_mutex_lock(&client->sendMutex);
#endif
  const int written = rfbWriteExact(client, reinterpret_cast<const char*>(bytes.data()), static_cast<int>(bytes.size()));
#ifdef LIBVNCSERVER_SEND_MUTEX
  pthread_mutex_unlock(&client->sendMutex);
#endif
  if (written < 0) {
    rfbCloseClient(client);
    return false;
  }
  return true;
}

bool write_fence(rfbClientPtr client, std::uint32_t flags, std::span<const std::uint8_t> payload) {
  return write_message(client, fence_message(flags, payload));
}

bool write_end_of_continuous_updates(rfbClientPtr client) {
  return write_message(client, end_of_continuous_updates_message());
}

}  // namespace rfbsim::detail
