// SPDX-License-Identifier: GPL-2.0-or-later
// Server::Impl's libvncserver callbacks, one client at a time on the network thread: a client arrives
// (ClientState created) or goes (its held keys released), sends keys or pointer, or gets an update (the
// JPEG quality imposed, bytes and time counted).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "client_state.hpp"
#include "rfbsim/log.hpp"
#include "server_impl.hpp"

namespace rfbsim {

using detail::ClientState;

namespace {

std::string peer_address(int fd) {
  sockaddr_storage peer{};
  socklen_t length = sizeof peer;
  if (::getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &length) != 0) return "?";
  if (peer.ss_family == AF_UNIX) return "local";  // a unix socket's peer has no address of its own
  char text[INET6_ADDRSTRLEN] = {};
  if (peer.ss_family == AF_INET6) {
    ::inet_ntop(AF_INET6, &reinterpret_cast<sockaddr_in6*>(&peer)->sin6_addr, text, sizeof text);
  } else {
    ::inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(&peer)->sin_addr, text, sizeof text);
  }
  return text;
}

}  // namespace

rfbNewClientAction Server::Impl::on_new_client(rfbClientPtr cl) {
  Impl& self = of(cl);
  // Set before refusing too: refused clients also pass through the hook (see on_client_gone).
  cl->clientGoneHook = on_client_gone;
  // A WebSocket whose request head came after the intake stopped waiting for it (it then took the client
  // for raw RFB): its Origin was never checked, so a browser-facing port turns it away. A real browser's
  // head comes with the connection's first packet; noVNC simply reconnects.
  if (cl->wsctx != nullptr && !self.adopting_head_checked && self.checks_origins()) {
    rfbsim::log::limited(rfbsim::log::Level::kWarn, "late-origin", "rfbsim.server",
                         "refusing a WebSocket whose request came too late to check its Origin");
    return RFB_CLIENT_REFUSE;
  }
  if (self.clients.load() >= self.options.max_clients) {
    rfbsim::log::limited(rfbsim::log::Level::kInfo, "clients-full", "rfbsim.server",
                         "refusing a client: %d of %d already connected", self.clients.load(),
                         self.options.max_clients);
    return RFB_CLIENT_REFUSE;
  }
  auto* state = new ClientState(self.streamer_config);
  state->info.id = self.next_client_id++;
  state->info.address = self.adopting_address.empty() ? peer_address(cl->sock) : self.adopting_address;
  state->info.websocket = cl->wsctx != nullptr;
  state->info.view_only = self.adopting_view_only;
  state->guard_fd = std::exchange(self.adopting_guard_fd, -1);
  state->connected = Clock::now();
  self.full_refusals = 0;
  cl->clientData = state;
  cl->clientFramebufferUpdateRequestHook = on_update_request;
  // libvncserver then drops the client's keys and pointer itself; on_key and on_pointer check again.
  cl->viewOnly = self.options.view_only || state->info.view_only ? TRUE : FALSE;
  ++self.clients;
  if (self.options.on_connect) self.options.on_connect(state->info);
  return RFB_CLIENT_ACCEPT;
}

void Server::Impl::on_client_gone(rfbClientPtr cl) {
  Impl& self = of(cl);
#if RFBSIM_LIBVNCSERVER_LEAKS_WSCTX
  // libvncserver up to 0.9.14 never frees a WebSocket client's context (about 46 KB a connection;
  // LibVNC/libvncserver#571, fixed after 0.9.14). Nothing reads it after this hook.
  std::free(cl->wsctx);
  cl->wsctx = nullptr;
#endif
  auto* state = static_cast<ClientState*>(cl->clientData);
  if (state == nullptr) return;
  cl->clientData = nullptr;
  self.watchdog.forget(state->guard_fd);
  ::close(state->guard_fd);
  const int remaining = --self.clients;
  // Keys this client held would otherwise stay down forever in the simulation.
  const auto now = Clock::now();
  for (const auto& release : self.held_keys.release_client(state->info.id, now)) self.input.push(release);
  if (remaining == 0) {
    for (const auto& release : self.held_keys.release_all(now)) self.input.push(release);
  }
  if (self.options.on_disconnect) self.options.on_disconnect(state->info);
  delete state;
}

void Server::Impl::on_key(rfbBool down, rfbKeySym keysym, rfbClientPtr cl) {
  Impl& self = of(cl);
  const auto* state = static_cast<ClientState*>(cl->clientData);
  if (self.options.view_only || state == nullptr || state->info.view_only) return;
  InputEvent event;
  event.kind = InputEvent::Kind::Key;
  event.time = Clock::now();
  event.client_id = state->info.id;
  event.keysym = keysym;
  event.down = down != 0;
  self.held_keys.record(event);
  self.input.push(event);
}

void Server::Impl::on_pointer(int mask, int x, int y, rfbClientPtr cl) {
  Impl& self = of(cl);
  const auto* state = static_cast<ClientState*>(cl->clientData);
  if (self.options.view_only || state == nullptr || state->info.view_only) return;
  InputEvent event;
  event.kind = InputEvent::Kind::Pointer;
  event.time = Clock::now();
  event.client_id = state->info.id;
  event.x = x;
  event.y = y;
  event.buttons = static_cast<std::uint8_t>(mask);
  self.input.push(event);
}

detail::ClientQualityRequest Server::Impl::requested_quality(rfbClientPtr cl) {
  return {cl->tightQualityLevel, cl->turboQualityLevel, cl->turboSubsampLevel, cl->tightCompressLevel};
}

void Server::Impl::on_update_start(rfbClientPtr cl) {
  auto* state = static_cast<ClientState*>(cl->clientData);
  if (state == nullptr) return;
  state->update_started = Clock::now();
  state->bytes_before_update = rfbStatGetSentBytes(cl);
  // What the client asked for (its latest SetEncodings, as libvncserver parsed it): the top of its ladder.
  state->asked = requested_quality(cl);
  state->streamer.client_requested(state->asked);
  // Impose the server's JPEG quality and subsampling on Tight clients, capped by the client's request; the
  // client's streamer lowers it while its link cannot carry the frame rate. Undone in on_update_done.
  if (const auto level = state->streamer.tight_quality()) {
    cl->turboQualityLevel = level->jpeg_quality;
    cl->turboSubsampLevel = level->subsampling;
    cl->tightQualityLevel = std::min(9, level->jpeg_quality / 10);
  }
}

void Server::Impl::on_update_request(rfbClientPtr cl, rfbFramebufferUpdateRequestMsg* request) {
  // A full (non-incremental) request means the client lost its picture: H.264 restarts with an IDR.
  auto* state = static_cast<ClientState*>(cl->clientData);
  if (state == nullptr) return;
  ++state->streamer.protocol().update_requests;
  if (request->incremental == 0) state->streamer.protocol().full_update_requested = true;
}

void Server::Impl::on_update_done(rfbClientPtr cl, int /*result*/) {
  Impl& self = of(cl);
  auto* state = static_cast<ClientState*>(cl->clientData);
  if (state == nullptr) return;
  // The client's own request back in place (libvncserver calls this hook on every path after on_update_start;
  // its Tight encoder also clamps tightCompressLevel in place, which this undoes too).
  cl->tightQualityLevel = state->asked.quality_level;
  cl->turboQualityLevel = state->asked.jpeg_quality;
  cl->turboSubsampLevel = state->asked.subsampling;
  cl->tightCompressLevel = state->asked.compress_level;
  // libvncserver's byte counter is an int that wraps after 2 GiB: subtract as unsigned 32-bit.
  const std::uint32_t sent = static_cast<std::uint32_t>(rfbStatGetSentBytes(cl)) -
                             static_cast<std::uint32_t>(state->bytes_before_update);
  // The hook also runs when libvncserver found nothing to send; that is no update.
  if (sent == 0) return;
  const auto now = Clock::now();
  const auto elapsed = now - state->update_started;
  state->streamer.tight_update_written(now, sent);
  self.encode_ns += static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed).count());
  self.bytes_sent += sent;
  ++self.updates_sent;
}

}  // namespace rfbsim
