// SPDX-License-Identifier: GPL-2.0-or-later
// Server::Impl's intake of new connections: accepted (in batches, pausing while descriptors run out),
// held in a bounded list until their PROXY line is read when one is expected and their first bytes tell
// what they speak, then handed on: plain HTTP to the HTTP service, raw RFB and RFB over WebSocket (once
// its page's Origin passed) to libvncserver. Waiting connections are watched by an edge-triggered epoll
// set, so bytes that are there but not yet enough wake the thread once, not on every pass.
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

#include "http_request.hpp"
#include "origin_policy.hpp"
#include "proxy_header.hpp"
#include "rfbsim/log.hpp"
#include "server_impl.hpp"
#include "static_files.hpp"

namespace rfbsim {

namespace {

// Asked-for socket send buffer (the kernel caps it at twice net.core.wmem_max): room for one whole update
// on top of kMaxUnsentBytes, so that starting an update does not block either.
constexpr int kSendBufferBytes = 1024 * 1024;
// How long accepting pauses when the process (or the system) is out of descriptors or memory: the
// listening socket stays readable meanwhile, and retrying at once would spin.
constexpr auto kAcceptPause = std::chrono::milliseconds(100);
// Distinct refused origins named in the log; a page that retries forever is named once.
constexpr std::size_t kMaxLoggedOrigins = 64;
// Longest origin text put in the log.
constexpr std::size_t kMaxLoggedOriginBytes = 200;

// Whether accept4 failed for lack of descriptors or kernel memory (retrying at once cannot help).
bool out_of_resources(int error) {
  return error == EMFILE || error == ENFILE || error == ENOBUFS || error == ENOMEM;
}

}  // namespace

void Server::Impl::accept_new(Clock::time_point now) {
  if (now < accept_paused_until) return;
  // At most one cap's worth per pass: each batch is classified before the next is taken, so that a client
  // whose request is already there is judged before a flood queued behind it pushes it out of the list.
  for (int taken = 0; taken < options.max_pending_connections; ++taken) {
    const int fd = ::accept4(listener.fd, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) {
      if (errno == EINTR || errno == ECONNABORTED) continue;  // that connection left; others may wait
      if (out_of_resources(errno)) pause_accepting(now, errno);
      return;  // EAGAIN: no more for now
    }
    if (accept_refusals > 0) {
      rfbsim::log::warn("rfbsim.server", "accepting connections again after %llu refused tries",
                        static_cast<unsigned long long>(accept_refusals));
      accept_refusals = 0;
    }
    add_pending(fd, now);
  }
}

void Server::Impl::pause_accepting(Clock::time_point now, int error) {
  accept_paused_until = now + kAcceptPause;
  if (accept_refusals++ == 0) {
    rfbsim::log::warn("rfbsim.server", "cannot accept connections: %s; trying again every %lld ms",
                      std::strerror(error), static_cast<long long>(kAcceptPause.count()));
  }
}

void Server::Impl::add_pending(int fd, Clock::time_point now) {
  // Full: the oldest waiting connection makes room. Each waits at most its sniff or PROXY timeout anyway,
  // so only a flood reaches the cap, and then the newest connections are the likeliest to be real.
  if (static_cast<int>(pending.size()) >= options.max_pending_connections) {
    if (pending_evicted++ == 0) {
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "intake-backlog", "rfbsim.server",
                           "more than %d connections waiting to be classified: closing the oldest "
                           "(logged once)",
                           options.max_pending_connections);
    }
    ::close(pending.front().fd);  // its only descriptor: closing also takes it out of the epoll set
    pending.erase(pending.begin());
  }
  epoll_event event{};
  event.events = EPOLLIN | EPOLLRDHUP | EPOLLET;
  event.data.fd = fd;
  if (::epoll_ctl(pending_epoll, EPOLL_CTL_ADD, fd, &event) != 0) {
    rfbsim::log::warn("rfbsim.server", "refusing a connection: cannot watch it (%s)", std::strerror(errno));
    ::close(fd);
    return;
  }
  pending.push_back({fd, now, !options.proxy_protocol, "", false});
}

std::vector<PendingConnection>::iterator Server::Impl::release_pending(std::vector<PendingConnection>::iterator it) {
  ::epoll_ctl(pending_epoll, EPOLL_CTL_DEL, it->fd, nullptr);
  return pending.erase(it);
}

void Server::Impl::classify_pending() {
  const auto now = Clock::now();
  for (auto it = pending.begin(); it != pending.end();) {
    char peeked[detail::kMaxHttpHeadBytes + 1];
    const auto n = ::recv(it->fd, peeked, sizeof peeked, MSG_PEEK | MSG_DONTWAIT);
    if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
      ::close(it->fd);  // left before saying anything
      it = release_pending(it);
      continue;
    }
    const std::string_view bytes(peeked, n > 0 ? static_cast<std::size_t>(n) : 0U);
    if (!it->proxied) {
      if (!take_proxy_header(*it, bytes, now)) {
        ::close(it->fd);
        it = release_pending(it);
        continue;
      }
      if (!it->proxied) {
        ++it;  // the line is still coming
        continue;
      }
      if (!serves_http) {
        const PendingConnection connection = *it;
        it = release_pending(it);
        adopt_rfb(connection, true);
        continue;
      }
      ++it;  // sniff the client's own bytes when they come (the epoll set reports them)
      continue;
    }
    auto protocol = detail::sniff_protocol(bytes);
    if (protocol == detail::WireProtocol::Undecided && now - it->accepted >= sniff_timeout()) {
      // Silence means a raw RFB client waiting for our greeting; a half-sent HTTP head gets its error.
      protocol = bytes.empty() ? detail::WireProtocol::Rfb : detail::WireProtocol::Http;
    }
    if (protocol == detail::WireProtocol::Undecided) {
      ++it;
      continue;
    }
    // Out of the list and the epoll set before the socket goes elsewhere (adopt_rfb duplicates it, and an
    // epoll registration lives as long as any duplicate does).
    const PendingConnection connection = *it;
    it = release_pending(it);
    switch (protocol) {
      case detail::WireProtocol::Undecided:
        break;
      case detail::WireProtocol::Rfb:
        adopt_rfb(connection, false);
        break;
      case detail::WireProtocol::WebSocket:
        if (admit_websocket(connection.fd, bytes)) adopt_rfb(connection, true);
        break;
      case detail::WireProtocol::Http:
        // Nothing is served over HTTP here: closed unanswered, as libvncserver would a bad RFB client.
        if (serves_http) {
          http->serve(connection.fd);
        } else {
          ::close(connection.fd);
        }
        break;
    }
  }
}

bool Server::Impl::take_proxy_header(PendingConnection& connection, std::string_view bytes, Clock::time_point now) {
  const detail::ProxyHeader header = detail::parse_proxy_header(bytes);
  switch (header.status) {
    case detail::ProxyHeader::Status::Incomplete:
      if (now - connection.accepted < options.read_timeout) return true;
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "proxy-line", "rfbsim.server",
                           "closing a connection: no PROXY line within %lld ms",
                           static_cast<long long>(options.read_timeout.count()));
      return false;
    case detail::ProxyHeader::Status::Invalid:
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "proxy-line", "rfbsim.server",
                           "closing a connection: it did not begin with a PROXY line");
      return false;
    case detail::ProxyHeader::Status::Valid: break;
  }
  // Consume exactly the line: what follows is the client's own.
  char line[detail::kMaxProxyHeaderBytes];
  const auto n = ::recv(connection.fd, line, header.length, MSG_DONTWAIT);
  if (n != static_cast<ssize_t>(header.length)) return false;
  connection.proxied = true;
  connection.address = header.source;
  connection.view_only = header.view_only;
  connection.accepted = now;  // the sniff's clock starts with the client's own bytes
  return true;
}

bool Server::Impl::admit_websocket(int fd, std::string_view head) {
  // Behind a relay (PROXY lines) this port is not browser-facing: the relay checked the page's origin.
  if (options.proxy_protocol) return true;
  const detail::HttpParseResult parsed = detail::parse_http_request(head);
  const auto origin = parsed.request.headers.find("origin");
  // No Origin: not a browser (browsers always send one with an upgrade), so no page to distrust.
  if (origin == parsed.request.headers.end()) return true;
  if (detail::websocket_origin_allowed(origin->second, parsed.request.header("host"), options.allowed_origins)) {
    return true;
  }
  log_refused_origin(origin->second);
  // Take the request off the socket first: closing with unread bytes would reset the connection and the
  // browser might never see the answer.
  char discard[detail::kMaxHttpHeadBytes + 1];
  [[maybe_unused]] const auto taken = ::recv(fd, discard, sizeof discard, MSG_DONTWAIT);
  const std::string body = "403 Forbidden: pages from this origin may not open the stream (see --allow-origin)\n";
  const std::string answer = detail::response_head(403, "text/plain; charset=utf-8", body.size()) + body;
  // A fresh socket's buffer takes the whole small answer; a peer that cannot take it loses nothing of value.
  [[maybe_unused]] const auto sent = ::send(fd, answer.data(), answer.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
  ::shutdown(fd, SHUT_WR);
  ::close(fd);
  return false;
}

void Server::Impl::log_refused_origin(const std::string& origin) {
  ++origins_refused;
  if (logged_origins.count(origin) != 0) return;
  if (logged_origins.size() >= kMaxLoggedOrigins) {
    if (logged_origins.size() == kMaxLoggedOrigins) {
      logged_origins.insert("");  // marks that the log said so once
      rfbsim::log::warn("rfbsim.server", "more refused origins than the log names; they are only counted");
    }
    return;
  }
  logged_origins.insert(origin);
  rfbsim::log::warn("rfbsim.server",
                    "refused a WebSocket from a page at '%.*s': neither this server's page, nor "
                    "loopback, nor allowed by --allow-origin (logged once per origin)",
                    static_cast<int>(std::min(origin.size(), kMaxLoggedOriginBytes)), origin.c_str());
}

void Server::Impl::adopt_rfb(const PendingConnection& connection, bool head_checked) {
  const int fd = connection.fd;
  // Full: refused here, before libvncserver's own WebSocket sniff, which holds this thread up to 100 ms
  // for every silent connection (so a flood of idle connections costs nothing once the slots are taken).
  if (clients.load() >= options.max_clients) {
    if (full_refusals++ == 0) {
      rfbsim::log::info("rfbsim.server",
                        "refusing clients: %d of %d already connected (logged once until "
                        "one is accepted)",
                        clients.load(), options.max_clients);
    }
    ::close(fd);
    return;
  }
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);  // fails harmlessly on a unix socket
  ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &kSendBufferBytes, sizeof kSendBufferBytes);
  // libvncserver takes the socket over: it runs the WebSocket handshake if there is one (under the
  // watchdog, so a handshake sent byte by byte cannot hold the thread), then RFB. On failure it closes
  // the socket itself; our duplicate keeps the watchdog's descriptor valid meanwhile.
  const int guard = ::fcntl(fd, F_DUPFD_CLOEXEC, 0);
  if (guard < 0) {
    rfbsim::log::limited(rfbsim::log::Level::kWarn, "out-of-fds", "rfbsim.server",
                         "refusing a client: out of file descriptors");
    ::close(fd);
    return;
  }
  adopting_guard_fd = guard;
  adopting_address = connection.address;
  adopting_view_only = connection.view_only;
  adopting_head_checked = head_checked;
  watchdog.arm(guard, Clock::now() + options.read_timeout);
  rfbNewClient(screen, fd);
  watchdog.disarm();
  // on_new_client takes the duplicate when it accepts the client; otherwise it is ours to close.
  if (adopting_guard_fd >= 0) ::close(std::exchange(adopting_guard_fd, -1));
}

}  // namespace rfbsim
