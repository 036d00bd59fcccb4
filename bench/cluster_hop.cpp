// SPDX-License-Identifier: GPL-2.0-or-later
// bench_cluster (b): /healthz round trips and RFB Fence round trips over a session's WebSocket (a WsRfbBridge
// to the manager's relay), each straight to the manager and through HAProxy, interleaved.
//
// A Fence with the Request flag is answered by the session at once (rfbproto: the responder echoes the
// payload), so its round trip is the path's own latency: bridge, WebSocket, relay, session and back, with no
// rendering or encoding in it. The bridge is the same on both paths; the difference is HAProxy's hop.
#include "cluster_hop.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "bench_util.hpp"
#include "ws_rfb_bridge.hpp"

namespace rfbsim::bench {

namespace {

using namespace std::chrono_literals;

constexpr std::uint8_t kFence = 248;
constexpr std::uint8_t kEndOfContinuousUpdates = 150;
constexpr std::uint32_t kFenceRequest = 0x80000000U;
constexpr std::int32_t kPseudoEncodingFence = -312;

// A raw RFB 3.8 client with no picture: handshake, SetEncodings (raw + Fence), then fences only.
class FenceClient {
 public:
  explicit FenceClient(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(static_cast<std::uint16_t>(port));
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd_ < 0 || ::connect(fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
      throw std::runtime_error("fence client: cannot connect to the bridge");
    }
    const int on = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    // Version, security None, ClientInit (shared), ServerInit.
    read_exact(12);
    write_all("RFB 003.008\n");
    const std::string types = read_exact(static_cast<std::size_t>(static_cast<std::uint8_t>(read_exact(1)[0])));
    if (types.find('\x01') == std::string::npos) throw std::runtime_error("fence client: no security type None");
    write_all(std::string(1, '\x01'));
    if (read_u32() != 0) throw std::runtime_error("fence client: security refused");
    write_all(std::string(1, '\x01'));
    read_exact(20);
    read_exact(read_u32());  // the desktop name
    std::string encodings{'\x02', '\x00', '\x00', '\x02'};
    append_u32(encodings, 0);
    append_u32(encodings, static_cast<std::uint32_t>(kPseudoEncodingFence));
    write_all(encodings);
  }
  ~FenceClient() { ::close(fd_); }
  FenceClient(const FenceClient&) = delete;
  FenceClient& operator=(const FenceClient&) = delete;

  /// One fence round trip in milliseconds.
  double round_trip(std::uint64_t serial) {
    std::string payload(8, '\0');
    std::memcpy(payload.data(), &serial, 8);
    std::string fence{static_cast<char>(kFence), 0, 0, 0};
    append_u32(fence, kFenceRequest);
    fence += static_cast<char>(payload.size());
    fence += payload;
    const auto sent = Clock::now();
    write_all(fence);
    for (;;) {
      const auto type = static_cast<std::uint8_t>(read_exact(1)[0]);
      if (type == kEndOfContinuousUpdates) continue;
      if (type != kFence) throw std::runtime_error("fence client: unexpected message " + std::to_string(type));
      read_exact(3);
      const std::uint32_t flags = read_u32();
      const std::string echoed = read_exact(static_cast<std::uint8_t>(read_exact(1)[0]));
      if ((flags & kFenceRequest) != 0) {  // the server's own fence: answer it, as a client must
        std::string answer{static_cast<char>(kFence), 0, 0, 0};
        append_u32(answer, flags & 3U);
        answer += static_cast<char>(echoed.size());
        write_all(answer + echoed);
        continue;
      }
      if (echoed == payload) return ms_between(sent, Clock::now());
    }
  }

 private:
  static void append_u32(std::string& out, std::uint32_t value) {
    for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((value >> shift) & 0xff);
  }
  std::uint32_t read_u32() {
    const std::string bytes = read_exact(4);
    std::uint32_t value = 0;
    for (const char byte : bytes) value = (value << 8) | static_cast<std::uint8_t>(byte);
    return value;
  }
  std::string read_exact(std::size_t size) {
    std::string out(size, '\0');
    std::size_t got = 0;
    while (got < size) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 10000) <= 0) throw std::runtime_error("fence client: no answer within 10 s");
      const ssize_t n = ::recv(fd_, out.data() + got, size - got, 0);
      if (n <= 0) throw std::runtime_error("fence client: the connection closed");
      got += static_cast<std::size_t>(n);
    }
    return out;
  }
  void write_all(const std::string& bytes) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) throw std::runtime_error("fence client: the connection closed");
      sent += static_cast<std::size_t>(n);
    }
  }
  int fd_ = -1;
};

// `count` fence round trips over a fresh WebSocket to `url`.
void fences(const std::string& url, int count, std::uint64_t& serial, std::vector<double>& out) {
  test::WsRfbBridge bridge(url);
  FenceClient client(bridge.port());
  for (int i = 0; i < count; ++i) out.push_back(client.round_trip(serial++));
}

}  // namespace

HopSamples measure_hop(const test::ClusterUnderTest& cluster, const HopOptions& options) {
  HopSamples samples;
  // Requests: direct and proxied in turn, each on its own connection, to the same manager.
  const test::ClusterHost& host = cluster.hosts().front();
  for (int i = 0; i < options.requests; ++i) {
    for (const bool proxied : {false, true}) {
      const auto begin = Clock::now();
      const auto response = proxied ? cluster.get("/" + host.id + "/healthz") : cluster.get_direct(host.id, "/healthz");
      if (response.status != 200) throw std::runtime_error("GET /healthz answered " + std::to_string(response.status));
      (proxied ? samples.request_proxied : samples.request_direct).push_back(ms_between(begin, Clock::now()));
    }
  }

  // Frames: one session on that host; blocks of 100 fences per WebSocket, direct and proxied in turn (a
  // session takes one participant connection at a time, so the two never overlap).
  const test::StartResult started = cluster.start("uid=hop-bench", "/" + host.id + "/start");
  if (started.token.empty()) throw std::runtime_error("no session for the hop bench: " + started.response.raw);
  const std::string path = "/" + host.id + "/s/" + started.token + "/ws";
  std::uint64_t serial = 1;
  for (int done = 0; done < options.frames; done += 100) {
    const int block = std::min(100, options.frames - done);
    fences("ws://127.0.0.1:" + std::to_string(host.port) + path, block, serial, samples.frame_direct);
    fences("ws://127.0.0.1:" + std::to_string(cluster.port()) + path, block, serial, samples.frame_proxied);
  }
  return samples;
}

}  // namespace rfbsim::bench
