// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim::Server: libvncserver driven from one network thread that owns the framebuffer.
//
// Why one thread: libvncserver's threaded mode encodes from per-client threads that read the framebuffer
// while the host writes it. Here a single thread alternates between copying the newest frame's changed
// tiles into the framebuffer and letting libvncserver read input and encode updates, so nothing is ever
// encoded while it is being written (no tearing), and the simulation thread only ever touches the mailbox.
#include "rfbsim/server.hpp"

#include <linux/sockios.h>
#include <poll.h>
#include <rfb/rfb.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>

#include "client_state.hpp"
#include "origin_policy.hpp"
#include "rfb_extension.hpp"
#include "rfbsim/log.hpp"
#include "server_impl.hpp"

namespace rfbsim {

using detail::ClientState;

namespace {

// Poll timeout when nothing is pending; only bounds how fast the thread notices a stop request.
constexpr int kIdlePollMs = 200;
// Poll timeout while a client's output is backed up: how often we look whether it has drained.
constexpr int kBackedUpPollMs = 5;
// Flow control: no new update is started for a client while more than this many bytes of earlier ones
// are still unsent in its socket. A client on a slow link then gets fewer, always current, frames instead
// of a growing backlog, and writing its updates never blocks the thread that serves everyone.
constexpr int kMaxUnsentBytes = 128 * 1024;

// libvncserver's log goes through these global hooks; keep its chatter off unless asked for.
bool vnc_log_enabled() {
  static const bool enabled = std::getenv("RFBSIM_VNC_LOG") != nullptr;
  return enabled;
}
void vnc_log(const char* format, ...) {
  if (!vnc_log_enabled()) return;
  std::fputs("[rfbsim.vnc] ", stderr);
  va_list args;
  va_start(args, format);
  std::vfprintf(stderr, format, args);
  va_end(args);
}

// Bytes written to a socket that the peer has not yet acknowledged (TCP) or read.
int unsent_bytes(int fd) {
  int queued = 0;
  if (::ioctl(fd, SIOCOUTQ, &queued) != 0) return 0;
  return queued;
}

// libvncserver's index of Tight subsampling levels: 0 = 4:4:4, 1 = 4:2:0, 2 = 4:2:2, 3 = grey.
int turbo_subsampling_index(Subsampling s) {
  switch (s) {
    case Subsampling::k444: return 0;
    case Subsampling::k420: return 1;
    case Subsampling::k422: return 2;
    case Subsampling::kGray: return 3;
  }
  return 1;
}

ServerOptions validated(ServerOptions o) {
  if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192) {
    throw std::runtime_error("bad frame size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                             " (each side must be 16..8192)");
  }
  if (o.jpeg_quality < 0 || o.jpeg_quality > 100) throw std::runtime_error("jpeg_quality must be 0..100");
  if (o.max_clients < 1) throw std::runtime_error("max_clients must be at least 1");
  if (o.frame_rate < 1 || o.frame_rate > 240) throw std::runtime_error("frame_rate must be 1..240");
  if (o.read_timeout.count() < 1 || o.write_timeout.count() < 1) {
    throw std::runtime_error("read_timeout and write_timeout must be at least 1 ms");
  }
  if (!o.web_root.empty() && !std::filesystem::is_regular_file(std::filesystem::path(o.web_root) / "index.html")) {
    throw std::runtime_error("web root '" + o.web_root + "' has no index.html");
  }
  for (const auto& origin : o.allowed_origins) {
    if (const std::string error = detail::allowed_origin_error(origin); !error.empty()) throw std::runtime_error(error);
  }
  if (o.max_pending_connections < 1) throw std::runtime_error("max_pending_connections must be at least 1");
  for (const auto& route : o.json_routes) {
    if (route.first.empty() || route.first.front() != '/') {
      throw std::runtime_error("json route '" + route.first + "' must start with '/'");
    }
  }
  return o;
}

}  // namespace

Server::Impl::Impl(ServerOptions o)
    : options(validated(std::move(o))),
      serves_http(!options.web_root.empty() || !options.json_routes.empty()),
      mailbox(options.width, options.height),
      damage(options.width, options.height) {
  // libvncserver reports ordinary disconnects ("read: Connection reset by peer") on its error channel
  // too, so both channels stay quiet unless RFBSIM_VNC_LOG is set; our own failures are reported below.
  rfbLog = vnc_log;
  rfbErr = vnc_log;
  detail::register_streaming_extension();
  streamer_config.width = options.width;
  streamer_config.height = options.height;
  streamer_config.frame_rate = options.frame_rate;
  streamer_config.jpeg_quality = options.jpeg_quality;
  streamer_config.subsampling = turbo_subsampling_index(options.subsampling);
  streamer_config.adaptive_quality = options.adaptive_quality && options.jpeg_quality > 0;
  streamer_config.codec = options.codec;

  listener = options.unix_socket_path.empty() ? detail::open_listener(options.bind_address, options.port)
                                              : detail::open_unix_listener(options.unix_socket_path);
  wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  pending_epoll = ::epoll_create1(EPOLL_CLOEXEC);
  if (wake_fd < 0 || pending_epoll < 0) {
    const std::string cause = std::strerror(errno);
    detail::close_listener(listener);
    if (wake_fd >= 0) ::close(wake_fd);
    if (pending_epoll >= 0) ::close(pending_epoll);
    throw std::runtime_error("cannot create an eventfd or epoll set: " + cause);
  }

  // The framebuffer starts a neutral dark grey until the first frame arrives.
  framebuffer.assign(static_cast<std::size_t>(options.width) * static_cast<std::size_t>(options.height) * 4U, 0);
  for (std::size_t i = 0; i < framebuffer.size(); i += 4) {
    framebuffer[i] = framebuffer[i + 1] = framebuffer[i + 2] = 40;
    framebuffer[i + 3] = 255;
  }

  int argc = 1;
  char program[] = "rfbsim";
  char* argv[] = {program, nullptr};
  screen = rfbGetScreen(&argc, argv, options.width, options.height, 8, 3, 4);
  if (screen == nullptr) {
    detail::close_listener(listener);
    ::close(wake_fd);
    ::close(pending_epoll);
    throw std::runtime_error("libvncserver could not create a screen");
  }
  // Our frames are RGBA bytes: red in the lowest byte of each little-endian 32-bit pixel.
  screen->serverFormat.redShift = 0;
  screen->serverFormat.greenShift = 8;
  screen->serverFormat.blueShift = 16;
  screen->frameBuffer = reinterpret_cast<char*>(framebuffer.data());
  screen->desktopName = options.desktop_name.c_str();
  screen->screenData = this;
  // We own the listening socket (to serve HTTP on the same port); libvncserver listens on nothing.
  screen->autoPort = FALSE;
  screen->port = 0;
  screen->ipv6port = 0;
  screen->httpPort = 0;
  screen->httpDir = nullptr;
  screen->alwaysShared = TRUE;  // several viewers of one session (participant + researcher) coexist
  screen->deferUpdateTime = 0;  // frames already arrive in whole batches
  // libvncserver waits this long for each next byte of a message (the watchdog bounds the whole message).
  screen->maxClientWait = static_cast<int>(options.read_timeout.count());
  screen->newClientHook = on_new_client;
  screen->kbdAddEvent = on_key;
  screen->ptrAddEvent = on_pointer;
  screen->displayHook = on_update_start;
  screen->displayFinishedHook = on_update_done;
  screen->cursor = nullptr;  // the participant's own pointer is enough; no cursor pseudo-encoding
  rfbInitServer(screen);

  detail::HttpServiceConfig http_config;
  http_config.web_root = options.web_root;
  http_config.json_routes = options.json_routes;
  http = std::make_unique<detail::HttpService>(std::move(http_config));

  thread = std::thread([this] { run(); });
}

Server::Impl::~Impl() {
  stopping = true;
  const std::uint64_t one = 1;
  [[maybe_unused]] auto n = ::write(wake_fd, &one, sizeof one);
  if (thread.joinable()) thread.join();
  // Tell browsers this is a shutdown, not a network failure: a WebSocket close frame, 1001 "going away"
  // (RFC 6455 5.5.1; a server's frames are unmasked). No update is being written now: the thread is gone.
  for (rfbClientPtr cl = screen->clientHead; cl != nullptr; cl = cl->next) {
    if (cl->sock == RFB_INVALID_SOCKET || cl->wsctx == nullptr) continue;
    constexpr unsigned char kGoingAway[] = {0x88, 0x02, 0x03, 0xE9};
    [[maybe_unused]] auto sent = ::send(cl->sock, kGoingAway, sizeof kGoingAway, MSG_DONTWAIT | MSG_NOSIGNAL);
  }
  // Closing the clients here runs on_client_gone on this thread.
  rfbShutdownServer(screen, TRUE);
  rfbScreenCleanup(screen);
  for (const auto& connection : pending) ::close(connection.fd);
  http.reset();
  detail::close_listener(listener);
  ::close(wake_fd);
  ::close(pending_epoll);
}

bool Server::Impl::checks_origins() const {
  if (options.proxy_protocol) return false;
  const auto& allowed = options.allowed_origins;
  return std::find(allowed.begin(), allowed.end(), "*") == allowed.end();
}

// Until the next thing that happens by the clock alone: a pending connection's sniff or PROXY timeout, the
// end of a pause in accepting, a look at backed-up clients; at most kIdlePollMs.
int Server::Impl::poll_timeout_ms() const {
  const auto now = Clock::now();
  auto next = now + std::chrono::milliseconds(any_backed_up ? kBackedUpPollMs : kIdlePollMs);
  for (const auto& connection : pending) {
    const Clock::duration wait = connection.proxied ? sniff_timeout() : Clock::duration(options.read_timeout);
    next = std::min(next, connection.accepted + wait);
  }
  if (accept_paused_until > now) next = std::min(next, accept_paused_until);
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(next - now);
  return static_cast<int>(std::max<std::int64_t>(left.count() + 1, 1));
}

void Server::Impl::drain_pending_events() {
  epoll_event events[64];
  while (::epoll_wait(pending_epoll, events, 64, 0) == 64) {
  }
}

void Server::Impl::run() {
  std::vector<pollfd> fds;
  while (!stopping) {
    // Wait for a new connection, a new frame, new bytes from a pending connection or a client message.
    // The listener sits out a pause in accepting: it stays readable while descriptors are short.
    fds.clear();
    if (Clock::now() >= accept_paused_until) fds.push_back({listener.fd, POLLIN, 0});
    fds.push_back({wake_fd, POLLIN, 0});
    fds.push_back({pending_epoll, POLLIN, 0});
    rfbClientIteratorPtr it = rfbGetClientIterator(screen);
    for (rfbClientPtr cl = rfbClientIteratorNext(it); cl != nullptr; cl = rfbClientIteratorNext(it)) {
      if (cl->sock != RFB_INVALID_SOCKET) fds.push_back({cl->sock, POLLIN, 0});
    }
    rfbReleaseClientIterator(it);
    ::poll(fds.data(), fds.size(), poll_timeout_ms());
    if (stopping) break;

    std::uint64_t wakes = 0;
    [[maybe_unused]] auto n = ::read(wake_fd, &wakes, sizeof wakes);
    drain_pending_events();
    accept_new(Clock::now());
    classify_pending();
    apply_newest_frame();
    serve_clients(fds);
  }
}

// Does what rfbProcessEvents does for our kind of server (no listening socket of libvncserver's, no
// file transfer), but one client at a time under the watchdog, and with flow control on updates.
void Server::Impl::serve_clients(const std::vector<pollfd>& polled) {
  // 1. Read what the clients sent: input, update requests, handshake steps.
  for (rfbClientPtr cl = screen->clientHead; cl != nullptr; cl = cl->next) {
    if (cl->sock == RFB_INVALID_SOCKET) continue;
    const auto* state = static_cast<ClientState*>(cl->clientData);
    const auto it = std::find_if(polled.begin(), polled.end(), [&](const pollfd& p) { return p.fd == cl->sock; });
    if (state == nullptr || it == polled.end() || (it->revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
    watchdog.arm(state->guard_fd, Clock::now() + options.read_timeout);
    rfbProcessClientMessage(cl);
    // A WebSocket frame can carry several RFB messages; what libvncserver already decoded is not
    // visible to poll, so keep reading while its buffer holds some.
    while (cl->sock != RFB_INVALID_SOCKET && cl->wsctx != nullptr && webSocketsHasDataInBuffer(cl)) {
      watchdog.arm(state->guard_fd, Clock::now() + options.read_timeout);
      rfbProcessClientMessage(cl);
    }
    watchdog.disarm();
    // What the messages negotiated (Fence, ContinuousUpdates) is announced once, after them. A new quality
    // request is taken at once too, so that the status shows it even for a client whose updates are H.264.
    if (cl->sock != RFB_INVALID_SOCKET && cl->clientData != nullptr) {
      watchdog.arm(state->guard_fd, Clock::now() + options.write_timeout);
      static_cast<ClientState*>(cl->clientData)->streamer.client_requested(requested_quality(cl));
      static_cast<ClientState*>(cl->clientData)->streamer.after_messages(cl);
      watchdog.disarm();
    }
  }

  // 2. Send updates to the clients that are due one (asked for, or pushed while their link has room).
  const auto now = Clock::now();
  any_backed_up = false;
  for (rfbClientPtr cl = screen->clientHead; cl != nullptr; cl = cl->next) {
    if (cl->sock == RFB_INVALID_SOCKET || !may_send_update(cl, now)) continue;
    auto* state = static_cast<ClientState*>(cl->clientData);
    watchdog.arm(state->guard_fd, now + options.write_timeout);
    const auto sent = state->streamer.serve(cl, now, framebuffer.data());
    watchdog.disarm();
    // Tight updates are counted by the update hooks; H.264 ones are written by the streamer itself.
    if (sent.bytes > 0) {
      bytes_sent += sent.bytes;
      encode_ns += static_cast<std::uint64_t>(sent.encode.count());
      ++updates_sent;
    }
  }
  publish_streams(now);

  drop_stalled_handshakes(now);

  // 3. Forget the clients that left or were dropped above (this runs on_client_gone).
  for (rfbClientPtr cl = screen->clientHead; cl != nullptr;) {
    rfbClientPtr next = cl->next;
    if (cl->sock == RFB_INVALID_SOCKET) rfbClientConnectionGone(cl);
    cl = next;
  }
}

void Server::Impl::drop_stalled_handshakes(Clock::time_point now) {
  for (rfbClientPtr cl = screen->clientHead; cl != nullptr; cl = cl->next) {
    const auto* state = static_cast<const ClientState*>(cl->clientData);
    if (cl->sock == RFB_INVALID_SOCKET || state == nullptr || cl->state == rfbClientRec::RFB_NORMAL) continue;
    if (now - state->connected < kHandshakeTimeout) continue;
    rfbsim::log::limited(
        rfbsim::log::Level::kInfo, "client-dropped", "rfbsim.server",
        "dropping client %d: no RFB handshake within %lld s", state->info.id,
        static_cast<long long>(std::chrono::duration_cast<std::chrono::seconds>(kHandshakeTimeout).count()));
    rfbCloseClient(cl);
  }
}

// Flow control for one client: false while its earlier output is still backed up; drops the client
// when it stays backed up for write_timeout.
bool Server::Impl::may_send_update(rfbClientPtr cl, Clock::time_point now) {
  auto* state = static_cast<ClientState*>(cl->clientData);
  if (state == nullptr) return false;
  if (unsent_bytes(cl->sock) <= kMaxUnsentBytes) {
    state->backed_up_since.reset();
    return true;
  }
  if (!state->backed_up_since) state->backed_up_since = now;
  if (now - *state->backed_up_since >= options.write_timeout) {
    // By id only: the address may be a participant's (from a PROXY line), which logs must not hold.
    rfbsim::log::limited(rfbsim::log::Level::kInfo, "client-dropped", "rfbsim.server",
                         "dropping client %d: it read nothing for %lld ms", state->info.id,
                         static_cast<long long>(options.write_timeout.count()));
    ++backed_up_drops;
    rfbCloseClient(cl);
    return false;
  }
  any_backed_up = true;
  return false;
}

void Server::Impl::apply_newest_frame() {
  if (!mailbox.take(incoming)) return;
  const FrameView current{framebuffer.data(), options.width, options.height, 0};
  const FrameView next{incoming.data(), options.width, options.height, 0};
  if (damage.compare(current, next) == 0) {
    ++frames_applied;
    return;
  }
  const std::size_t row_bytes = static_cast<std::size_t>(options.width) * 4U;
  for (const PixelRect& rect : damage.changed_rects()) {
    for (int y = rect.y; y < rect.y + rect.h; ++y) {
      const std::size_t offset = static_cast<std::size_t>(y) * row_bytes + static_cast<std::size_t>(rect.x) * 4U;
      std::memcpy(framebuffer.data() + offset, incoming.data() + offset, static_cast<std::size_t>(rect.w) * 4U);
    }
    rfbMarkRectAsModified(screen, rect.x, rect.y, rect.x + rect.w, rect.y + rect.h);
  }
  tiles_changed += static_cast<std::uint64_t>(damage.changed_count());
  ++frames_applied;
  const auto now = Clock::now();
  for (rfbClientPtr cl = screen->clientHead; cl != nullptr; cl = cl->next) {
    if (auto* state = static_cast<ClientState*>(cl->clientData)) state->streamer.frame_changed(now);
  }
}

// The status snapshot that client_streams() hands out, refreshed a few times a second.
void Server::Impl::publish_streams(Clock::time_point now) {
  constexpr auto kEvery = std::chrono::milliseconds(100);
  if (now - streams_published < kEvery) return;
  streams_published = now;
  std::vector<ClientStreamStatus> fresh;
  for (rfbClientPtr cl = screen->clientHead; cl != nullptr; cl = cl->next) {
    if (const auto* state = static_cast<const ClientState*>(cl->clientData)) {
      fresh.push_back(state->streamer.status(state->info.id, now, cl->preferredEncoding));
    }
  }
  const std::lock_guard lock(streams_mutex);
  streams = std::move(fresh);
}
Server::Server(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
Server::~Server() = default;

int Server::port() const { return impl_->listener.port; }

std::string Server::url() const {
  if (!impl_->listener.unix_path.empty()) return "unix:" + impl_->listener.unix_path;
  const std::string& address = impl_->options.bind_address;
  const bool ipv6 = address.find(':') != std::string::npos;
  const std::string host = ipv6 ? "[" + address + "]" : address;
  if (impl_->options.web_root.empty()) return "vnc://" + host + ":" + std::to_string(port());
  return "http://" + host + ":" + std::to_string(port()) + "/";
}

void Server::submit(const FrameView& frame) {
  if (frame.pixels == nullptr || frame.width != impl_->options.width || frame.height != impl_->options.height) {
    throw std::invalid_argument("Server::submit: frame is " + std::to_string(frame.width) + "x" +
                                std::to_string(frame.height) + ", server is " + std::to_string(impl_->options.width) +
                                "x" + std::to_string(impl_->options.height));
  }
  impl_->mailbox.post(frame);
  ++impl_->frames_submitted;
  const std::uint64_t one = 1;
  [[maybe_unused]] auto n = ::write(impl_->wake_fd, &one, sizeof one);
}

std::vector<InputEvent> Server::poll_input() { return impl_->input.drain(); }

int Server::client_count() const { return impl_->clients.load(); }

ServerStats Server::stats() const {
  ServerStats s;
  s.frames_submitted = impl_->frames_submitted.load();
  s.frames_applied = impl_->frames_applied.load();
  s.tiles_changed = impl_->tiles_changed.load();
  s.updates_sent = impl_->updates_sent.load();
  s.bytes_sent = impl_->bytes_sent.load();
  s.encode_ms = static_cast<double>(impl_->encode_ns.load()) / 1e6;
  s.http_requests = impl_->http->requests();
  s.clients = impl_->clients.load();
  s.stalled_clients_dropped = impl_->watchdog.fired() + impl_->backed_up_drops.load();
  return s;
}

std::vector<ClientStreamStatus> Server::client_streams() const {
  const std::lock_guard lock(impl_->streams_mutex);
  return impl_->streams;
}

const ServerOptions& Server::options() const { return impl_->options; }

}  // namespace rfbsim

