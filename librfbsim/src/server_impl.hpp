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
#include <set>
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
// A server with nothing to serve over HTTP waits less (kRfbOnlySniffTimeout, see Impl::serves_http).
constexpr auto kSniffTimeout = std::chrono::milliseconds(500);
// The same wait on a port that serves no HTTP: there only a WebSocket upgrade's head is worth waiting for,
// and a browser sends it with the connection's first packet, so a short wait tells it from a raw RFB client.
constexpr auto kRfbOnlySniffTimeout = std::chrono::milliseconds(100);
// How long a client may take to finish the RFB handshake (version, security, init: a few round trips and
// no human step). Until then it holds one of max_clients, so an idle connection must not keep it.
constexpr auto kHandshakeTimeout = std::chrono::seconds(10);

// A connection accepted but not yet known to be HTTP, WebSocket or raw RFB.
struct PendingConnection {
  int fd = -1;
  Clock::time_point accepted{};
  bool proxied = false;   // its PROXY line was read (or none is expected)
  std::string address;    // from the PROXY line; "" = the socket's peer
  bool view_only = false; // its PROXY line marked it view-only (the relay's watcher)
};

struct Server::Impl {
  explicit Impl(ServerOptions o);
  ~Impl();

  void run();
  // Accepts a batch of new connections into `pending`, unless accepting is paused.
  void accept_new(Clock::time_point now);
  // Out of descriptors or memory: no accepting for a while (the listener stays readable), logged once.
  void pause_accepting(Clock::time_point now, int error);
  // Puts a new connection on the intake list and in its epoll set, closing the oldest one if full.
  void add_pending(int fd, Clock::time_point now);
  // Takes a connection off the intake list and out of the epoll set (the socket stays open).
  std::vector<PendingConnection>::iterator release_pending(std::vector<PendingConnection>::iterator it);
  void classify_pending();
  // Whether a WebSocket upgrade whose head is `head` may go on (its Origin passed); false after answering
  // it 403 and closing the socket.
  bool admit_websocket(int fd, std::string_view head);
  void log_refused_origin(const std::string& origin);
  // Hands a connection (already off the intake list) to libvncserver; its address (from a PROXY line)
  // replaces the socket's peer if given, and a view-only mark makes it a viewer whose input is dropped.
  // `head_checked`: a WebSocket head, if any, has been seen and its Origin admitted (or needs none).
  void adopt_rfb(const PendingConnection& connection, bool head_checked);
  // How long a connection's first bytes may take before it is judged by what came (see kSniffTimeout).
  [[nodiscard]] Clock::duration sniff_timeout() const {
    return serves_http ? Clock::duration(kSniffTimeout) : Clock::duration(kRfbOnlySniffTimeout);
  }
  // Whether WebSocket upgrades must pass the Origin check here (a browser-facing port that allows not all).
  [[nodiscard]] bool checks_origins() const;
  // Reads a pending connection's PROXY line once it is whole. False: close the connection (no valid line).
  bool take_proxy_header(PendingConnection& connection, std::string_view bytes, Clock::time_point now);
  // Reads the pending connections' readiness from their epoll set, so that it reports only new events.
  void drain_pending_events();
  void apply_newest_frame();
  // Drops clients still in the RFB handshake kHandshakeTimeout after they came: each holds a client slot.
  void drop_stalled_handshakes(Clock::time_point now);
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
  /// The quality and compression `cl` asked for in its latest SetEncodings, as libvncserver parsed them into its
  /// rfbClientRec (valid between updates: on_update_done puts the client's values back after each).
  static detail::ClientQualityRequest requested_quality(rfbClientPtr cl);
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
  std::vector<PendingConnection> pending; // network thread only; oldest first, at most max_pending_connections
  int pending_epoll = -1;                 // edge-triggered readiness of the pending connections
  Clock::time_point accept_paused_until{};  // no accept4 before this (out of descriptors)
  std::uint64_t accept_refusals = 0;      // accept4 failures for lack of resources since the last success
  std::uint64_t pending_evicted = 0;      // pending connections closed to make room
  std::uint64_t origins_refused = 0;      // WebSocket upgrades refused for their Origin
  std::set<std::string> logged_origins;   // refused origins already named in the log (bounded)
  std::uint64_t full_refusals = 0;        // clients refused for max_clients since one was last accepted
  std::unique_ptr<detail::HttpService> http;
  detail::CallWatchdog watchdog;          // cuts off a client that blocks the network thread
  int adopting_guard_fd = -1;             // handed from adopt_rfb to on_new_client
  std::string adopting_address;           // handed from adopt_rfb to on_new_client; "" = the socket's peer
  bool adopting_head_checked = false;     // handed from adopt_rfb to on_new_client
  bool adopting_view_only = false;        // handed from adopt_rfb to on_new_client
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
