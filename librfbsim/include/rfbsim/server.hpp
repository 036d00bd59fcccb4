// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim::Server: serves submitted frames to RFB and WebSocket (noVNC) clients on one port and
// collects their keys and pointer.
//
// Contract with the host program (the simulator):
//   - The host owns its pixels; submit() copies the frame, so the view may be reused right after.
//   - submit() and poll_input() may be called from any one thread (the simulation thread); they never
//     wait for the network: a slow or stalled client costs frames, never simulation time.
//   - The server owns one network thread, started by the constructor and joined by the destructor.
//     Callbacks in ServerOptions and the handlers of json routes run on that thread: keep them short
//     and thread-safe.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rfbsim/frame.hpp"
#include "rfbsim/input.hpp"

namespace rfbsim {

/// JPEG chroma subsampling for Tight encoding.
enum class Subsampling : std::uint8_t { k444, k422, k420, kGray };

/// Which picture encoding clients get. Tight JPEG works with every client; H.264 (the open H.264
/// rectangle, RFB encoding 50) only with clients that offer it (noVNC >= 1.6 in a browser with WebCodecs,
/// which needs a secure context: https, or http on localhost).
enum class Codec : std::uint8_t {
  kAuto,  ///< Tight JPEG first; H.264 for a client that offers it once its link cannot carry the frame rate
          ///< at the configured JPEG quality (then it stays on H.264)
  kJpeg,  ///< Tight JPEG always
  kH264,  ///< H.264 for every client that offers it, Tight JPEG for the others
};

/// One client's stream as the server sees it now, for status pages.
struct ClientStreamStatus {
  int id = 0;                       ///< ClientInfo::id
  std::string encoding;             ///< what the client gets: "tight", "zrle", "hextile", "raw", "h264", ...
  bool continuous_updates = false;  ///< updates pushed (ContinuousUpdates) rather than requested
  bool fence = false;               ///< the client answers fences (congestion control is possible)
  double base_rtt_ms = -1;          ///< lowest round trip seen through fences; -1 = not measured yet
  double last_rtt_ms = -1;          ///< the latest round trip; -1 = not measured yet
  std::uint32_t window_bytes = 0;   ///< congestion window: bytes allowed in flight
  std::uint64_t in_flight_bytes = 0;  ///< bytes sent and not yet known to have arrived
  std::uint64_t updates_sent = 0;   ///< framebuffer updates sent to this client
  std::uint64_t updates_held = 0;   ///< new frames held back because the link was full (they coalesce)
  std::uint64_t update_requests = 0;  ///< FramebufferUpdateRequests received (few once continuous)
  int quality = 0;                  ///< JPEG quality in use (Tight), or the top one (H.264); 0 = none applies
  int quality_level = 0;            ///< 0 = the top (the configured quality, or the client's lower one); each step
                                    ///< down is one more
  /// JPEG quality 1..100 the client asked for (a Tight quality level through libvncserver's table, or TurboVNC's
  /// fine level); 0 = it asked none. `quality` never exceeds it, nor the server's jpeg_quality.
  int requested_quality = 0;
  int requested_quality_level = -1;  ///< the Tight quality level 0..9 the client asked for; -1 = none
  int compress_level = 6;           ///< the Tight zlib level 0..9 the client asked for (libvncserver's 6 if none)
  double delivery_mbit = 0;         ///< the link's measured rate while full, Mbit/s; 0 = unknown
  double fps = 0;                   ///< updates per second over the last second or so
};

/// A client as the connect and disconnect callbacks see it.
struct ClientInfo {
  int id = 0;               ///< unique per server, counting from 1
  std::string address;      ///< peer address, e.g. "127.0.0.1"
  bool websocket = false;   ///< true when the client came in through WebSocket (a browser)
  /// true when the trusted relay marked the connection view-only (its PROXY line was exactly
  /// "PROXY UNKNOWN view-only", see ServerOptions::proxy_protocol): a watcher, whose keys and pointer are
  /// dropped. A server-wide ServerOptions::view_only drops everyone's input but leaves this false.
  bool view_only = false;
};

/// Counters since the server started. Encode time covers encoding and writing updates.
struct ServerStats {
  std::uint64_t frames_submitted = 0;  ///< submit() calls
  std::uint64_t frames_applied = 0;    ///< frames copied into the framebuffer (latest wins)
  std::uint64_t tiles_changed = 0;     ///< tiles copied into the framebuffer
  std::uint64_t updates_sent = 0;      ///< framebuffer updates sent, summed over clients
  std::uint64_t bytes_sent = 0;        ///< bytes written by those updates (RFB level)
  double encode_ms = 0.0;              ///< milliseconds spent encoding and sending updates
  std::uint64_t http_requests = 0;     ///< plain HTTP requests answered (page, files, json)
  int clients = 0;                     ///< RFB clients connected now
  std::uint64_t stalled_clients_dropped = 0;  ///< clients cut off by read_timeout or write_timeout
};

/// Definition of a server; start from the defaults and change what you need.
struct ServerOptions {
  int port = 0;                              ///< TCP port; 0 picks a free one (see Server::port())
  std::string bind_address = "127.0.0.1";    ///< IPv4 address to listen on; loopback unless told otherwise
  int width = 1280;                          ///< framebuffer width in pixels (16..8192)
  int height = 720;                          ///< framebuffer height in pixels (16..8192)
  int jpeg_quality = 80;                     ///< 1..100, imposed on Tight clients; 0 = respect the client's level
  Subsampling subsampling = Subsampling::k420;  ///< imposed together with jpeg_quality
  /// Lower JPEG quality (then frame rate) for a client whose link cannot carry the frame rate, and raise it
  /// again when it can; refresh a still picture at full quality. Needs jpeg_quality > 0 and a client that
  /// does ContinuousUpdates and Fence (noVNC); others get jpeg_quality always.
  bool adaptive_quality = true;
  Codec codec = Codec::kAuto;                ///< see Codec
  int frame_rate = 30;                       ///< the rate the host submits frames at (H.264 timing), 1..240
  int max_clients = 4;                       ///< further RFB clients are refused
  bool view_only = false;                    ///< ignore every key and pointer event
  std::string desktop_name = "rfbsim";       ///< the name RFB clients show
  /// Directory served to plain HTTP GETs; empty = none. With neither a web root nor json_routes the port
  /// speaks RFB only (raw, or over WebSocket): a silent raw RFB client is served after at most 100 ms
  /// instead of the up to 500 ms that tell it from a browser about to send its request (the request head
  /// is still read first, to check its Origin), a plain HTTP request is closed unanswered, and behind proxy_protocol
  /// a connection is handed to RFB as soon as its PROXY line is read.
  std::string web_root;
  /// A client that takes longer than this to send one whole message (input, update request, handshake
  /// step) is dropped: the one network thread waits for it meanwhile.
  std::chrono::milliseconds read_timeout{1000};
  /// A client whose earlier updates stay unsent this long (it stopped reading) is dropped; until then it
  /// gets no new updates and others are served as usual.
  std::chrono::milliseconds write_timeout{5000};
  std::function<void(const ClientInfo&)> on_connect;     ///< network thread; may be empty
  std::function<void(const ClientInfo&)> on_disconnect;  ///< network thread; may be empty
  /// Extra JSON endpoints on the same port, e.g. {"/status.json", fn}; fn runs on an HTTP worker thread
  /// and returns the body. Paths must start with '/'. Empty, and with no web_root: RFB only (see web_root).
  std::map<std::string, std::function<std::string()>> json_routes;
  /// Every connection must begin with a PROXY protocol version 1 line (HAProxy's), whose source address
  /// becomes the client's ClientInfo::address. For a trusted relay in front of the server, such as
  /// sim_manager's, so that the server knows the participant's address rather than the relay's. A
  /// connection without a valid line within read_timeout is closed. The line "PROXY UNKNOWN view-only"
  /// (the relay's watcher) makes a view-only client (ClientInfo::view_only). Never enable it on a port
  /// that untrusted peers reach directly: they could claim any address.
  bool proxy_protocol = false;
  /// Pages whose WebSocket upgrades are accepted besides the server's own page (the request's Host, over
  /// http or https) and loopback pages (http(s)://127.0.0.1, localhost or [::1], any port): exact
  /// "scheme://host[:port]" entries (host case-insensitive), or "*" for any page. An upgrade with another
  /// Origin gets 403; one without Origin (not a browser) is accepted. Not checked on proxy_protocol
  /// connections: their relay checks origins itself.
  std::vector<std::string> allowed_origins;
  /// Accepted connections still being classified (PROXY line or first bytes not complete) at most; one
  /// more closes the oldest of them, so a flood of idle connections cannot grow memory or starve new ones.
  int max_pending_connections = 64;
  /// Listen on this unix stream socket (created mode 0600: only this user may connect) instead of TCP;
  /// `port` and `bind_address` are then ignored. A stale socket file there is replaced, any other file is
  /// an error; the file is removed when the server stops. Empty = TCP.
  std::string unix_socket_path;
};

/// Serves frames over RFB (raw TCP) and RFB-over-WebSocket on one port, plus optional static files and
/// JSON routes over plain HTTP.
class Server {
 public:
  /// Binds, listens and starts the network thread. Throws std::runtime_error naming the cause
  /// (bad size, address not valid, port in use, web root missing, bad allowed origin, socket path taken).
  explicit Server(ServerOptions options);
  /// Stops the network thread, closes every connection and releases held keys.
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// The port actually bound (useful with port 0); 0 on a unix socket.
  [[nodiscard]] int port() const;
  /// The URL that opens the web page (or the RFB endpoint when there is no web root); "unix:PATH" on a
  /// unix socket.
  [[nodiscard]] std::string url() const;
  /// Copies one frame (must be the server's size) into the latest-wins mailbox; never blocks on the
  /// network. Throws std::invalid_argument on a size mismatch.
  void submit(const FrameView& frame);
  /// Removes and returns every input event since the last call, in arrival order.
  std::vector<InputEvent> poll_input();
  /// RFB clients connected now.
  [[nodiscard]] int client_count() const;
  /// A snapshot of the counters.
  [[nodiscard]] ServerStats stats() const;
  /// Each connected client's stream (codec, round trip, window, quality); safe from any thread, at most
  /// one network-thread pass old.
  [[nodiscard]] std::vector<ClientStreamStatus> client_streams() const;
  /// The options the server runs with.
  [[nodiscard]] const ServerOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim
