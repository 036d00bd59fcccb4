// SPDX-License-Identifier: GPL-2.0-or-later
// ClientState: what the server keeps per RFB client, owned through rfbClientRec::clientData (created in
// the new-client hook, deleted in the client-gone hook; libvncserver 0.9.14 never calls an extension's
// close, so this is the one place per-client state lives). Network thread only.
#pragma once

#include <chrono>
#include <optional>

#include "client_streamer.hpp"
#include "rfbsim/server.hpp"

namespace rfbsim::detail {

struct ClientState {
  explicit ClientState(const StreamerConfig& config) : streamer(config) {}

  ClientInfo info;
  std::chrono::steady_clock::time_point connected{};  // when libvncserver took the client (handshake deadline)
  int guard_fd = -1;  // our dup of the client's socket, for the watchdog (libvncserver may close its own)
  std::optional<std::chrono::steady_clock::time_point> backed_up_since;  // output above the unsent limit since
  std::chrono::steady_clock::time_point update_started{};
  int bytes_before_update = 0;
  // The client's own quality fields as libvncserver parsed them, kept across each update: the update hook
  // imposes ours in rfbClientRec for the update and puts these back afterwards, so that rfbClientRec always
  // holds the client's request between updates (a later SetEncodings overwrites it there).
  ClientQualityRequest asked;
  ClientStreamer streamer;  // negotiation, congestion control, quality and codec of this client's updates
};

}  // namespace rfbsim::detail
