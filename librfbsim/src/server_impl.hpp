// SPDX-License-Identifier: GPL-2.0-or-later
// Server::Impl: the state of one rfbsim::Server and its network thread, shared by the files that implement
// it: server.cpp (the loop: frames in, messages read, updates out), server_intake.cpp (new connections:
// PROXY lines, HTTP or RFB), server_hooks.cpp (libvncserver's per-client callbacks: clients coming and
// going, keys, pointer, updates). Everything here belongs to the network thread unless marked atomic or
// guarded by a mutex.
#pragma once

#include <poll.h>
#include <rfb/rfb.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "call_watchdog.hpp"
#include "client_streamer.hpp"
#include "frame_mailbox.hpp"
#include "held_keys.hpp"
#include "http_service.hpp"
#include "listener.hpp"
#include "rfbsim/input.hpp"
#include "rfbsim/server.hpp"
#include "rfbsim/tile_damage.hpp"

namespace rfbsim {

using Clock = std::chrono::steady_clock;

// How long a silent new connection may take to show whether it speaks HTTP. Raw RFB clients wait for the
// server to speak first, so they are only recognised by this timeout; browsers send their request at once.
// A server with nothing to serve over HTTP skips this wait (see Impl::serves_http).
constexpr auto kSniffTimeout = std::chrono::milliseconds(500);

// A connection accepted but not yet known to be HTTP, WebSocket or raw RFB.
struct PendingConnection {
  int fd = -1;
  Clock::time_point accepted{};
  bool proxied = false;   // its PROXY line was read (or none is expected)
  std::string address;    // from the PROXY line; "" = the socket's peer
};

struct Server::Impl {
  explicit Impl(ServerOptions o);
  ~Impl();

  void run();
  void accept_new();
  void classify_pending();
  // Hands a connection to libvncserver; `address` (from a PROXY line) replaces the socket's peer if given.
  void adopt_rfb(int fd, const std::string& address = "");
  // Reads a pending connection's PROXY line once it is whole. False: close the connection (no valid line).
  bool take_proxy_header(PendingConnection& connection, std::string_view bytes, Clock::time_point now);
  void apply_newest_frame();
  void serve_clients(const std::vector<pollfd>& polled);
  bool may_send_update(rfbClientPtr cl, Clock::time_point now);
  int poll_timeout_ms() const;

  // libvncserver hooks (C function pointers); `self` comes from screen->screenData.
  static Impl& of(rfbClientPtr cl) { return *static_cast<Impl*>(cl->screen->screenData); }
  static rfbNewClientAction on_new_client(rfbClientPtr cl);
  static void on_client_gone(rfbClientPtr cl);
  static void on_key(rfbBool down, rfbKeySym keysym, rfbClientPtr cl);
  static void on_pointer(int mask, int x, int y, rfbClientPtr cl);
  static void on_update_start(rfbClientPtr cl);
  static void on_update_done(rfbClientPtr cl, int result);
  static void on_update_request(rfbClientPtr cl, rfbFramebufferUpdateRequestMsg* request);
  void publish_streams(Clock::time_point now);

  ServerOptions options;
  // Whether plain HTTP has anything to get here (a web root or a json route). Without it every new
  // connection goes to libvncserver at once: sniffing would only delay raw RFB clients by kSniffTimeout.
  bool serves_http = false;
  detail::Listener listener;
  int wake_fd = -1;
  rfbScreenInfoPtr screen = nullptr;
  std::vector<std::uint8_t> framebuffer;  // what clients see; written only by the network thread
  std::vector<std::uint8_t> incoming;     // the frame taken from the mailbox
  detail::FrameMailbox mailbox;
  TileDamage damage;
  InputQueue input;
  detail::HeldKeys held_keys;             // network thread only
  std::vector<PendingConnection> pending; // network thread only
  std::unique_ptr<detail::HttpService> http;
  detail::CallWatchdog watchdog;          // cuts off a client that blocks the network thread
  int adopting_guard_fd = -1;             // handed from adopt_rfb to on_new_client
  std::string adopting_address;           // handed from adopt_rfb to on_new_client; "" = the socket's peer
  bool any_backed_up = false;             // some client's output is above kMaxUnsentBytes
  detail::StreamerConfig streamer_config;  // what each client's ClientStreamer starts from
  Clock::time_point streams_published{};  // when `streams` was last refreshed
  mutable std::mutex streams_mutex;        // guards `streams` (read from any thread)
  std::vector<ClientStreamStatus> streams;
  int next_client_id = 1;

  std::atomic<bool> stopping{false};
  std::atomic<int> clients{0};
  std::atomic<std::uint64_t> frames_submitted{0};
  std::atomic<std::uint64_t> frames_applied{0};
  std::atomic<std::uint64_t> tiles_changed{0};
  std::atomic<std::uint64_t> updates_sent{0};
  std::atomic<std::uint64_t> bytes_sent{0};
  std::atomic<std::uint64_t> encode_ns{0};
  std::atomic<std::uint64_t> backed_up_drops{0};
  std::thread thread;
};

}  // namespace rfbsim
