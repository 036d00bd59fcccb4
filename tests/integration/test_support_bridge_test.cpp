// SPDX-License-Identifier: GPL-2.0-or-later
// The network test helpers against real peers: RFB through WsRfbBridge to sim_rfb's WebSocket, bytes
// through the bridge to WsEchoServer over ws and wss, the test certificate through OpenSSL, and the
// HTTP(S) client against sim_rfb and a one-shot TLS server.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <openssl/pem.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <poll.h>
#include <stdlib.h>  // mkdtemp
#include <sys/socket.h>
#include <unistd.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "http_client.hpp"
#include "raw_socket.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"
#include "tls_test_cert.hpp"
#include "ws_echo_server.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::RawSocket;
using rfbsim::test::RfbTestClient;
using rfbsim::test::SimProcess;
using rfbsim::test::WsEchoServer;
using rfbsim::test::WsEchoServerOptions;
using rfbsim::test::WsRfbBridge;
using rfbsim::test::WsRfbBridgeOptions;
namespace net = rfbsim::test::net;

namespace {

const std::vector<std::string> kSmall = {"--port", "0", "--width", "320", "--height", "240"};

std::string ws_url(int port, const std::string& path) { return "ws://127.0.0.1:" + std::to_string(port) + path; }
std::string origin_of(int port) { return "http://127.0.0.1:" + std::to_string(port); }

// A fresh directory under /tmp, removed with everything in it at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "rfbsim_test_net_XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A loopback port that nothing listens on (bound, then released).
int unused_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  ::close(fd);
  return ntohs(address.sin_port);
}

// `size` bytes of a pattern that no shifted copy of itself matches (so reordering would show).
std::vector<std::uint8_t> pattern(std::size_t size) {
  std::vector<std::uint8_t> bytes(size);
  for (std::size_t i = 0; i < size; ++i) bytes[i] = static_cast<std::uint8_t>((i * 7 + i / 251) & 0xFF);
  return bytes;
}

// Whether the peer closes `socket` within `timeout` (anything it sends first is discarded).
bool closes_within(RawSocket& socket, std::chrono::milliseconds timeout) {
  bool closed = false;
  socket.read_until_closed(timeout, &closed);
  return closed;
}

template <typename T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const { Free(p); }
};
using CertPtr = std::unique_ptr<X509, Deleter<X509, X509_free>>;
using KeyPtr = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using StorePtr = std::unique_ptr<X509_STORE, Deleter<X509_STORE, X509_STORE_free>>;
using StoreContextPtr = std::unique_ptr<X509_STORE_CTX, Deleter<X509_STORE_CTX, X509_STORE_CTX_free>>;
using SslContextPtr = std::unique_ptr<SSL_CTX, Deleter<SSL_CTX, SSL_CTX_free>>;
using SslPtr = std::unique_ptr<SSL, Deleter<SSL, SSL_free>>;

CertPtr read_cert(const std::filesystem::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "r");
  if (file == nullptr) return nullptr;
  CertPtr cert(PEM_read_X509(file, nullptr, nullptr, nullptr));
  std::fclose(file);
  return cert;
}

KeyPtr read_key(const std::filesystem::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "r");
  if (file == nullptr) return nullptr;
  KeyPtr key(PEM_read_PrivateKey(file, nullptr, nullptr, nullptr));
  std::fclose(file);
  return key;
}

// A one-shot HTTPS server on a thread: accepts one TLS connection with the given certificate, reads
// one request head, answers `response` and closes. `request()` yields what it read ("" on failure).
class OneShotTlsServer {
 public:
  OneShotTlsServer(const rfbsim::test::TestCertificate& cert, std::string response) {
    context_.reset(SSL_CTX_new(TLS_server_method()));
    if (!context_ || SSL_CTX_use_certificate_file(context_.get(), cert.cert_pem.c_str(), SSL_FILETYPE_PEM) != 1 ||
        SSL_CTX_use_PrivateKey_file(context_.get(), cert.key_pem.c_str(), SSL_FILETYPE_PEM) != 1) {
      throw std::runtime_error("TLS server context");
    }
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof address;
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::listen(listen_fd_, 1) != 0 ||
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
      ::close(listen_fd_);
      throw std::runtime_error("TLS server socket");
    }
    port_ = ntohs(address.sin_port);
    request_ = std::async(std::launch::async, [this, answer = std::move(response)] { return serve(answer); });
  }
  ~OneShotTlsServer() {
    if (request_.valid()) request_.wait();
    ::close(listen_fd_);
  }
  OneShotTlsServer(const OneShotTlsServer&) = delete;
  OneShotTlsServer& operator=(const OneShotTlsServer&) = delete;

  [[nodiscard]] int port() const { return port_; }
  std::string request() { return request_.get(); }

 private:
  std::string serve(const std::string& answer) {
    // Bounded: gives up after 10 s without a client rather than hang the test.
    pollfd pfd{listen_fd_, POLLIN, 0};
    if (::poll(&pfd, 1, 10'000) != 1) return {};
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) return {};
    timeval limit{10, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
    SslPtr ssl(SSL_new(context_.get()));
    SSL_set_fd(ssl.get(), fd);
    std::string head;
    if (SSL_accept(ssl.get()) == 1) {
      char buffer[4096];
      while (head.find("\r\n\r\n") == std::string::npos) {
        const int n = SSL_read(ssl.get(), buffer, sizeof buffer);
        if (n <= 0) break;
        head.append(buffer, static_cast<std::size_t>(n));
      }
      SSL_write(ssl.get(), answer.data(), static_cast<int>(answer.size()));
      SSL_shutdown(ssl.get());
    }
    ssl.reset();
    ::close(fd);
    return head;
  }

  SslContextPtr context_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::future<std::string> request_;
};

}  // namespace

TEST_CASE("WsRfbBridge carries a libvncclient session to sim_rfb over WebSocket", "[integration][test_net]") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);
  WsRfbBridge bridge(ws_url(sim.port(), "/websockify"), origin_of(sim.port()));
  REQUIRE(bridge.port() > 0);
  CHECK(bridge.connection_count() == 0);

  // Two sessions one after the other, each on its own WebSocket.
  for (std::size_t round = 1; round <= 2; ++round) {
    INFO("round " << round);
    {
      RfbTestClient client("127.0.0.1", bridge.port());
      CHECK(client.width() == 320);
      CHECK(client.height() == 240);
      REQUIRE(client.wait_for_updates(1, 10s));
      const auto live = bridge.last();
      CHECK(live.opened);
      CHECK_FALSE(live.handshake_failed);
      CHECK(live.handshake_status == 101);
      CHECK(live.subprotocol == "binary");
      CHECK_FALSE(live.finished);
    }
    // The client closed its TCP socket: the bridge closes the WebSocket and records how it ended.
    REQUIRE(bridge.wait_last_finished(10s));
    CHECK(bridge.connection_count() == round);
    const auto ended = bridge.last();
    CHECK(ended.closed_by_bridge);
    CHECK(ended.close_code != -1);  // 1006: libvncserver drops the TCP connection without a close frame
    CHECK(ended.error.empty());
    CHECK(ended.bytes_to_server > 0);
    CHECK(ended.bytes_to_client > 0);
  }
}

TEST_CASE("WsRfbBridge records a refused handshake and its HTTP status", "[integration][test_net]") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);

  SECTION("an HTTP error answer") {
    // A header name with a space makes the head invalid HTTP, so sim_rfb answers 400 instead of 101.
    WsRfbBridgeOptions options;
    options.extra_headers = {{"Bad Header", "x"}};
    WsRfbBridge bridge(ws_url(sim.port(), "/websockify"), origin_of(sim.port()), options);
    CHECK_THROWS(RfbTestClient("127.0.0.1", bridge.port()));
    REQUIRE(bridge.wait_last_finished(10s));
    CHECK(bridge.last_handshake_failed());
    CHECK(bridge.last_handshake_status() == 400);
    CHECK(bridge.last_close_code() == -1);
    CHECK_FALSE(bridge.last().opened);
  }

  SECTION("nobody listening") {
    WsRfbBridge bridge(ws_url(unused_port(), "/s/abc/ws"), "");
    CHECK_THROWS(RfbTestClient("127.0.0.1", bridge.port()));
    REQUIRE(bridge.wait_last_finished(10s));
    CHECK(bridge.last_handshake_failed());
    CHECK(bridge.last_handshake_status() == 0);
    CHECK_FALSE(bridge.last().error.empty());
  }

  SECTION("not a WebSocket URL") {
    CHECK_THROWS_AS(WsRfbBridge("http://127.0.0.1:1/", ""), std::invalid_argument);
  }
}

TEST_CASE("WsRfbBridge relays bytes both ways and reports the server's close", "[integration][test_net]") {
  WsEchoServer server;
  WsRfbBridgeOptions options;
  SECTION("default flow control") {}
  SECTION("the TCP reader waits for every WebSocket send to drain") { options.max_ws_buffered_bytes = 0; }
  WsRfbBridge bridge(ws_url(server.port(), "/s/abc/ws?x=1"), "https://example.test", options);
  RawSocket client(bridge.port());
  REQUIRE(server.wait_opened(1, 5s));
  CHECK(server.last_origin() == "https://example.test");
  CHECK(server.last_resource() == "/s/abc/ws?x=1");

  // 8 MiB out and back while both directions run at once: order kept, nothing lost, no stall with
  // the TCP reader backing off behind the WebSocket's send queue.
  const std::vector<std::uint8_t> sent = pattern(std::size_t{8} << 20);
  std::future<bool> writer = std::async(std::launch::async, [&] { return client.send_all(sent, 10s); });
  std::vector<std::uint8_t> echoed;
  CHECK(client.read_exact(sent.size(), echoed, 10s));
  CHECK(writer.get());
  CHECK(echoed == sent);
  const auto live = bridge.last();
  CHECK(live.opened);
  CHECK(live.subprotocol == "binary");

  // The server ends the session: its code and reason are recorded and the TCP client sees the close.
  server.close_all(1001, "session expired");
  CHECK(closes_within(client, 5s));
  REQUIRE(bridge.wait_last_finished(5s));
  CHECK(bridge.last_close_code() == 1001);
  CHECK(bridge.last_close_reason() == "session expired");
  CHECK_FALSE(bridge.last().closed_by_bridge);
  // The byte counts are final once the connection is finished.
  CHECK(bridge.last().bytes_to_server == sent.size());
  CHECK(bridge.last().bytes_to_client == sent.size());
  CHECK(server.wait_all_closed(5s));

  // The next client gets a WebSocket of its own; this time the client leaves first.
  RawSocket second(bridge.port());
  REQUIRE(server.wait_opened(2, 5s));
  REQUIRE(second.send_all("ping"));
  std::vector<std::uint8_t> pong;
  CHECK(second.read_exact(4, pong, 5s));
  CHECK(pong == std::vector<std::uint8_t>{'p', 'i', 'n', 'g'});
  second.close();
  REQUIRE(bridge.wait_last_finished(5s));
  CHECK(bridge.connection_count() == 2);
  CHECK(bridge.last().closed_by_bridge);
  CHECK(bridge.last_close_code() == 1000);  // websocketpp's server echoes the bridge's own close
  CHECK(server.wait_all_closed(5s));
}

TEST_CASE("WsRfbBridge drops a TCP client that stops reading", "[integration][test_net]") {
  WsEchoServer server;
  WsRfbBridgeOptions options;
  options.max_tcp_queued_bytes = std::size_t{1} << 20;
  WsRfbBridge bridge(ws_url(server.port(), "/ws"), "", options);
  RawSocket client(bridge.port());
  REQUIRE(server.wait_opened(1, 5s));
  // Writes far more than the kernel buffers and the 1 MiB queue hold (up to 1 GiB, until the bridge
  // hangs up), and never reads the echo.
  const std::vector<std::uint8_t> chunk = pattern(std::size_t{1} << 20);
  int chunks = 0;
  while (chunks < 1024 && client.send_all(chunk)) ++chunks;
  CHECK(chunks < 1024);
  REQUIRE(bridge.wait_last_finished(10s));
  CHECK(bridge.last().closed_by_bridge);
  CHECK(bridge.last().error == "TCP client fell too far behind");
  CHECK(server.wait_all_closed(5s));
}

TEST_CASE("WsRfbBridge records a refusal's HTTP status", "[integration][test_net]") {
  WsEchoServerOptions options;
  options.reject_status = 403;
  WsEchoServer server(options);
  WsRfbBridge bridge(ws_url(server.port(), "/s/wrong/ws"), "");
  RawSocket client(bridge.port());
  CHECK(closes_within(client, 5s));
  REQUIRE(bridge.wait_last_finished(5s));
  CHECK(bridge.last_handshake_failed());
  CHECK(bridge.last_handshake_status() == 403);
  CHECK(server.last_origin().empty());  // an empty origin sends no Origin header
  CHECK(server.opened() == 0);
}

TEST_CASE("WsRfbBridge over wss with the test certificate", "[integration][test_net]") {
  TempDir dir;
  const auto cert = rfbsim::test::make_test_certificate(dir.path());
  WsEchoServer server({cert.cert_pem.string(), cert.key_pem.string(), 0});
  const std::string url = "wss://127.0.0.1:" + std::to_string(server.port()) + "/s/abc/ws";

  // Verification off (the default), and on with the certificate itself as the trust anchor.
  WsRfbBridgeOptions options;
  SECTION("no verification") {}
  SECTION("verified against cert.pem") {
    options.verify_certificate = true;
    options.ca_file = cert.cert_pem.string();
  }
  WsRfbBridge bridge(url, "https://127.0.0.1", options);
  RawSocket client(bridge.port());
  REQUIRE(client.send_all("hello over tls"));
  std::vector<std::uint8_t> echoed;
  CHECK(client.read_exact(14, echoed, 5s));
  CHECK(std::string(echoed.begin(), echoed.end()) == "hello over tls");
  CHECK(bridge.last().handshake_status == 101);
  client.close();
  REQUIRE(bridge.wait_last_finished(5s));
  CHECK(bridge.last_close_code() == 1000);
}

TEST_CASE("WsRfbBridge refuses an untrusted certificate when verifying", "[integration][test_net]") {
  TempDir dir;
  const auto cert = rfbsim::test::make_test_certificate(dir.path());
  WsEchoServer server({cert.cert_pem.string(), cert.key_pem.string(), 0});
  WsRfbBridgeOptions options;
  options.verify_certificate = true;  // against the system store, which does not know the test cert
  WsRfbBridge bridge("wss://127.0.0.1:" + std::to_string(server.port()) + "/ws", "", options);
  RawSocket client(bridge.port());
  CHECK(closes_within(client, 5s));
  REQUIRE(bridge.wait_last_finished(5s));
  CHECK(bridge.last_handshake_failed());
  CHECK(bridge.last_handshake_status() == 0);
  CHECK(server.opened() == 0);

  // A trust file that cannot be read is the test's own mistake: it throws at once.
  options.ca_file = (dir.path() / "missing.pem").string();
  CHECK_THROWS_AS(WsRfbBridge("wss://127.0.0.1:" + std::to_string(server.port()) + "/ws", "", options),
                  std::runtime_error);
}

TEST_CASE("make_test_certificate writes a key and a self-signed certificate OpenSSL accepts",
          "[integration][test_net]") {
  TempDir dir;
  const auto made = rfbsim::test::make_test_certificate(dir.path());
  CHECK(made.cert_pem == dir.path() / "cert.pem");
  CHECK(made.key_pem == dir.path() / "key.pem");
  CHECK((std::filesystem::status(made.key_pem).permissions() & std::filesystem::perms::all) ==
        (std::filesystem::perms::owner_read | std::filesystem::perms::owner_write));

  const CertPtr cert = read_cert(made.cert_pem);
  const KeyPtr key = read_key(made.key_pem);
  REQUIRE(cert);
  REQUIRE(key);

  // Signed by its own key, which matches the certificate's public key.
  CHECK(X509_verify(cert.get(), key.get()) == 1);
  CHECK(X509_check_private_key(cert.get(), key.get()) == 1);

  // Names: the SAN carries both the loopback IP and localhost; nothing else matches.
  CHECK(X509_check_ip_asc(cert.get(), "127.0.0.1", 0) == 1);
  CHECK(X509_check_host(cert.get(), "localhost", 0, 0, nullptr) == 1);
  CHECK(X509_check_host(cert.get(), "example.com", 0, 0, nullptr) == 0);

  // Valid now, for one day (the start is back-dated by a minute).
  int days = 0;
  int seconds = 0;
  REQUIRE(ASN1_TIME_diff(&days, &seconds, X509_get0_notBefore(cert.get()), X509_get0_notAfter(cert.get())) == 1);
  const int valid_for = days * 86400 + seconds;
  CHECK(std::abs(valid_for - (86400 + 60)) <= 1);  // the two ends are set by separate clock reads
  CHECK(X509_cmp_current_time(X509_get0_notBefore(cert.get())) < 0);
  CHECK(X509_cmp_current_time(X509_get0_notAfter(cert.get())) > 0);

  // Trusted as its own anchor, it verifies for a TLS server.
  StorePtr store(X509_STORE_new());
  REQUIRE(X509_STORE_add_cert(store.get(), cert.get()) == 1);
  StoreContextPtr verify(X509_STORE_CTX_new());
  REQUIRE(X509_STORE_CTX_init(verify.get(), store.get(), cert.get(), nullptr) == 1);
  X509_STORE_CTX_set_purpose(verify.get(), X509_PURPOSE_SSL_SERVER);
  CHECK(X509_verify_cert(verify.get()) == 1);
  INFO(X509_verify_cert_error_string(X509_STORE_CTX_get_error(verify.get())));
  CHECK(X509_STORE_CTX_get_error(verify.get()) == X509_V_OK);

  // A second call replaces the files with a new certificate.
  rfbsim::test::make_test_certificate(dir.path());
  const CertPtr again = read_cert(made.cert_pem);
  REQUIRE(again);
  CHECK(X509_cmp(cert.get(), again.get()) != 0);
}

TEST_CASE("net::http_get and net::http_request against sim_rfb's HTTP side", "[integration][test_net]") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);

  // A proper GET: 200 with a JSON document.
  const auto status = net::http_get(sim.port(), "/status.json");
  CHECK(status.status == 200);
  CHECK(status.headers.count("content-type") == 1);
  CHECK(status.headers.at("content-type").find("application/json") == 0);
  REQUIRE_FALSE(status.body.empty());
  CHECK(status.body.front() == '{');
  CHECK(std::isfinite(rfbsim::test::json_number(status.body, "tick")));

  // A header line without a colon: 400.
  const auto malformed = net::http_request(sim.port(), "GET /status.json HTTP/1.1\r\nno colon here\r\n\r\n");
  CHECK(malformed.status == 400);

  // A head far past the server's limit: 431, heard although the server stops reading early.
  const std::string huge = "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Pad: " + std::string(256 * 1024, 'a') + "\r\n\r\n";
  const auto oversized = net::http_request(sim.port(), huge);
  CHECK(oversized.status >= 400);
  CHECK(oversized.status < 500);

  // HEAD: complete at the end of the head, without waiting for the server to close.
  const auto head = net::http_request(
      sim.port(), "HEAD /status.json HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  CHECK(head.status == 200);
  CHECK(head.body.empty());

  // TLS against a plain port fails cleanly and quickly instead of hanging until the timeout.
  const auto started = std::chrono::steady_clock::now();
  const auto tls = net::http_get(sim.port(), "/status.json", {}, true, 5s);
  CHECK(tls.status == -1);
  CHECK(std::chrono::steady_clock::now() - started < 4s);

  // Nothing listening: -1.
  CHECK(net::http_get(unused_port(), "/").status == -1);
}

TEST_CASE("net::http_get over TLS with the test certificate", "[integration][test_net]") {
  TempDir dir;
  const auto cert = rfbsim::test::make_test_certificate(dir.path());
  OneShotTlsServer server(cert, "HTTP/1.1 200 OK\r\nContent-Type: text/plain\r\nContent-Length: 5\r\n"
                                "Set-Cookie: a=1\r\nSet-Cookie: b=2\r\n\r\nhello");
  const auto response = net::http_get(server.port(), "/s/abc/", {{"Origin", "https://127.0.0.1"}}, true);
  CHECK(response.status == 200);
  CHECK(response.body == "hello");
  CHECK(response.headers.at("set-cookie") == "a=1, b=2");
  const std::string request = server.request();
  CHECK(request.rfind("GET /s/abc/ HTTP/1.1\r\n", 0) == 0);
  CHECK(request.find("\r\nHost: 127.0.0.1:" + std::to_string(server.port()) + "\r\n") != std::string::npos);
  CHECK(request.find("\r\nOrigin: https://127.0.0.1\r\n") != std::string::npos);
  CHECK(request.find("\r\nConnection: close\r\n") != std::string::npos);
}

TEST_CASE("net::parse_http_response", "[integration][test_net]") {
  SECTION("chunked body, lower-cased names") {
    const auto r = net::parse_http_response(
        "HTTP/1.1 404 Not Found\r\nX-Thing:  v  \r\nTransfer-Encoding: chunked\r\n\r\n3\r\nabc\r\n2\r\nde\r\n0\r\n\r\n");
    CHECK(r.status == 404);
    CHECK(r.headers.at("x-thing") == "v");
    CHECK(r.body == "abcde");
  }
  SECTION("body cut to Content-Length") {
    const auto r = net::parse_http_response("HTTP/1.0 200 OK\r\nContent-Length: 2\r\n\r\nokEXTRA");
    CHECK(r.status == 200);
    CHECK(r.body == "ok");
  }
  SECTION("not HTTP") {
    CHECK(net::parse_http_response("").status == -1);
    CHECK(net::parse_http_response("RFB 003.008\n").status == -1);
    CHECK(net::parse_http_response("HTTP/1.1 2x0 OK\r\n\r\n").status == -1);
  }
}
