// SPDX-License-Identifier: GPL-2.0-or-later
// Server::Impl's intake of new connections: accepted, their PROXY line read when one is expected, then
// sniffed: plain HTTP goes to the HTTP service, raw RFB and RFB over WebSocket to libvncserver.
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <utility>

#include "http_request.hpp"
#include "proxy_header.hpp"
#include "server_impl.hpp"

namespace rfbsim {

namespace {

// Asked-for socket send buffer (the kernel caps it at twice net.core.wmem_max): room for one whole update
// on top of kMaxUnsentBytes, so that starting an update does not block either.
constexpr int kSendBufferBytes = 1024 * 1024;

}  // namespace

void Server::Impl::accept_new() {
  for (;;) {
    const int fd = ::accept4(listener.fd, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) return;  // EAGAIN: no more; other errors (EMFILE...) are retried on the next wake
    // Nothing HTTP to serve: whatever the peer speaks is libvncserver's to take (RFB, RFB over WebSocket)
    // or to refuse (a plain HTTP request, garbage), as if it owned the port.
    if (!serves_http && !options.proxy_protocol) {
      adopt_rfb(fd);
      continue;
    }
    pending.push_back({fd, Clock::now(), !options.proxy_protocol, ""});
  }
}

void Server::Impl::classify_pending() {
  const auto now = Clock::now();
  for (auto it = pending.begin(); it != pending.end();) {
    char peeked[detail::kMaxHttpHeadBytes + 1];
    const auto n = ::recv(it->fd, peeked, sizeof peeked, MSG_PEEK | MSG_DONTWAIT);
    if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
      ::close(it->fd);  // left before saying anything
      it = pending.erase(it);
      continue;
    }
    const std::string_view bytes(peeked, n > 0 ? static_cast<std::size_t>(n) : 0U);
    if (!it->proxied) {
      if (!take_proxy_header(*it, bytes, now)) {
        ::close(it->fd);
        it = pending.erase(it);
        continue;
      }
      if (!it->proxied) {
        ++it;  // the line is still coming
        continue;
      }
      if (!serves_http) {
        adopt_rfb(it->fd, it->address);
        it = pending.erase(it);
        continue;
      }
      ++it;  // sniff the client's own bytes at the next wake
      continue;
    }
    auto protocol = detail::sniff_protocol(bytes);
    if (protocol == detail::WireProtocol::Undecided && now - it->accepted >= kSniffTimeout) {
      // Silence means a raw RFB client waiting for our greeting; a half-sent HTTP head gets its error.
      protocol = bytes.empty() ? detail::WireProtocol::Rfb : detail::WireProtocol::Http;
    }
    switch (protocol) {
      case detail::WireProtocol::Undecided:
        ++it;
        continue;
      case detail::WireProtocol::Rfb:
      case detail::WireProtocol::WebSocket:
        adopt_rfb(it->fd, it->address);
        break;
      case detail::WireProtocol::Http:
        http->serve(it->fd);
        break;
    }
    it = pending.erase(it);
  }
}

bool Server::Impl::take_proxy_header(PendingConnection& connection, std::string_view bytes, Clock::time_point now) {
  const detail::ProxyHeader header = detail::parse_proxy_header(bytes);
  switch (header.status) {
    case detail::ProxyHeader::Status::Incomplete:
      if (now - connection.accepted < options.read_timeout) return true;
      std::fprintf(stderr, "[rfbsim.server] closing a connection: no PROXY line within %lld ms\n",
                   static_cast<long long>(options.read_timeout.count()));
      return false;
    case detail::ProxyHeader::Status::Invalid:
      std::fprintf(stderr, "[rfbsim.server] closing a connection: it did not begin with a PROXY line\n");
      return false;
    case detail::ProxyHeader::Status::Valid: break;
  }
  // Consume exactly the line: what follows is the client's own.
  char line[detail::kMaxProxyHeaderBytes];
  const auto n = ::recv(connection.fd, line, header.length, MSG_DONTWAIT);
  if (n != static_cast<ssize_t>(header.length)) return false;
  connection.proxied = true;
  connection.address = header.source;
  connection.accepted = now;  // the sniff's clock starts with the client's own bytes
  return true;
}

void Server::Impl::adopt_rfb(int fd, const std::string& address) {
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &kSendBufferBytes, sizeof kSendBufferBytes);
  // libvncserver takes the socket over: it runs the WebSocket handshake if there is one (under the
  // watchdog, so a handshake sent byte by byte cannot hold the thread), then RFB. On failure it closes
  // the socket itself; our duplicate keeps the watchdog's descriptor valid meanwhile.
  const int guard = ::fcntl(fd, F_DUPFD_CLOEXEC, 0);
  if (guard < 0) {
    std::fprintf(stderr, "[rfbsim.server] refusing a client: out of file descriptors\n");
    ::close(fd);
    return;
  }
  adopting_guard_fd = guard;
  adopting_address = address;
  watchdog.arm(guard, Clock::now() + options.read_timeout);
  rfbNewClient(screen, fd);
  watchdog.disarm();
  // on_new_client takes the duplicate when it accepts the client; otherwise it is ours to close.
  if (adopting_guard_fd >= 0) ::close(std::exchange(adopting_guard_fd, -1));
}

}  // namespace rfbsim
