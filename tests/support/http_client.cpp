// SPDX-License-Identifier: GPL-2.0-or-later
// The loopback HTTP client: a non-blocking socket driven by poll(), optionally wrapped in an OpenSSL
// TLS client, and a small response parser.
#include "http_client.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <openssl/err.h>
#include <openssl/ssl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <memory>

namespace rfbsim::test::net {

namespace {

using Clock = std::chrono::steady_clock;

std::string to_lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

// Milliseconds left until `deadline`, never negative (for poll()).
int millis_left(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left <= 0 ? 0 : static_cast<int>(std::min<long long>(left, 60'000));
}

// Holds SIGPIPE off the calling thread while it lives: OpenSSL writes with write(2), which raises
// SIGPIPE on a socket the server closed. A SIGPIPE raised meanwhile is consumed before unblocking.
class SigpipeGuard {
 public:
  SigpipeGuard() {
    sigset_t pipe_only;
    sigemptyset(&pipe_only);
    sigaddset(&pipe_only, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_only, &previous_);
  }
  ~SigpipeGuard() {
    sigset_t pending;
    sigpending(&pending);
    if (sigismember(&pending, SIGPIPE) == 1) {
      sigset_t pipe_only;
      sigemptyset(&pipe_only);
      sigaddset(&pipe_only, SIGPIPE);
      const timespec now{0, 0};
      sigtimedwait(&pipe_only, nullptr, &now);
    }
    pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
  }
  SigpipeGuard(const SigpipeGuard&) = delete;
  SigpipeGuard& operator=(const SigpipeGuard&) = delete;

 private:
  sigset_t previous_{};
};

// A connected non-blocking loopback socket, or -1 when the connect failed or took past `deadline`.
int connect_loopback(int port, Clock::time_point deadline) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    pollfd pfd{fd, POLLOUT, 0};
    int error = 0;
    socklen_t length = sizeof error;
    if (errno != EINPROGRESS || ::poll(&pfd, 1, millis_left(deadline)) != 1 ||
        ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &length) != 0 || error != 0) {
      ::close(fd);
      return -1;
    }
  }
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}

// One byte stream, plain or TLS, with non-blocking reads and writes that say which poll() event to
// wait for when they cannot progress.
class Stream {
 public:
  static constexpr long kAgain = -1;   // no progress now; wait for wait_events()
  static constexpr long kFailed = -2;  // the stream is broken

  Stream(int fd, SSL* ssl) : fd_(fd), ssl_(ssl) {}
  ~Stream() {
    if (ssl_ != nullptr) {
      SSL_shutdown(ssl_);  // one non-blocking attempt at close_notify; the answer is not awaited
      SSL_free(ssl_);
    }
    ::close(fd_);
  }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

  [[nodiscard]] int fd() const { return fd_; }

  // Completes the TLS handshake by `deadline`; true at once for a plain stream.
  bool handshake(Clock::time_point deadline) {
    if (ssl_ == nullptr) return true;
    for (;;) {
      const int result = SSL_connect(ssl_);
      if (result == 1) return true;
      short events = 0;
      if (!again(result, events)) return false;
      pollfd pfd{fd_, events, 0};
      if (::poll(&pfd, 1, millis_left(deadline)) <= 0) return false;
    }
  }

  // Bytes read (> 0), 0 at the end of the stream, kAgain or kFailed.
  long read(char* buffer, std::size_t size) {
    if (ssl_ == nullptr) {
      const auto n = ::recv(fd_, buffer, size, 0);
      if (n >= 0) return static_cast<long>(n);
      read_events_ = POLLIN;
      return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? kAgain : kFailed;
    }
    std::size_t n = 0;
    const int result = SSL_read_ex(ssl_, buffer, size, &n);
    if (result == 1) return static_cast<long>(n);
    if (SSL_get_error(ssl_, result) == SSL_ERROR_ZERO_RETURN) return 0;
    return again(result, read_events_) ? kAgain : kFailed;
  }

  // Bytes written (> 0), kAgain or kFailed.
  long write(const char* data, std::size_t size) {
    if (ssl_ == nullptr) {
      const auto n = ::send(fd_, data, size, MSG_NOSIGNAL);
      if (n >= 0) return static_cast<long>(n);
      write_events_ = POLLOUT;
      return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? kAgain : kFailed;
    }
    std::size_t n = 0;
    const int result = SSL_write_ex(ssl_, data, size, &n);
    if (result == 1) return static_cast<long>(n);
    return again(result, write_events_) ? kAgain : kFailed;
  }

  // The poll() events the last stalled read or write waits for (TLS may need the other direction).
  [[nodiscard]] short read_events() const { return read_events_; }
  [[nodiscard]] short write_events() const { return write_events_; }

 private:
  // Whether an OpenSSL call's failure only means "wait"; sets `events` to what to wait for.
  bool again(int result, short& events) {
    switch (SSL_get_error(ssl_, result)) {
      case SSL_ERROR_WANT_READ:
        events = POLLIN;
        return true;
      case SSL_ERROR_WANT_WRITE:
        events = POLLOUT;
        return true;
      default:
        ERR_clear_error();  // this thread's queue; a failed exchange is reported as status -1
        return false;
    }
  }

  int fd_;
  SSL* ssl_;
  short read_events_ = POLLIN;
  short write_events_ = POLLOUT;
};

struct SslContextFree {
  void operator()(SSL_CTX* context) const { SSL_CTX_free(context); }
};

// A TLS client context that accepts any certificate: tests talk to their own self-signed servers.
std::unique_ptr<SSL_CTX, SslContextFree> make_client_context() {
  std::unique_ptr<SSL_CTX, SslContextFree> context(SSL_CTX_new(TLS_client_method()));
  if (!context) return context;
  SSL_CTX_set_verify(context.get(), SSL_VERIFY_NONE, nullptr);
  // A server that closes without close_notify still ends the response (as a plain close does).
  SSL_CTX_set_options(context.get(), SSL_OP_IGNORE_UNEXPECTED_EOF);
  // Partial writes and a retry from the same (unmoved) buffer, as the write loop below does.
  SSL_CTX_set_mode(context.get(), SSL_MODE_ENABLE_PARTIAL_WRITE);
  return context;
}

// Whether `raw` already holds the whole response: the head of the answer to a HEAD request, or a head
// with Content-Length and that many body bytes. Otherwise the server's close ends it.
bool response_complete(const std::string& raw, bool head_only) {
  const auto blank = raw.find("\r\n\r\n");
  if (blank == std::string::npos) return false;
  if (head_only) return true;
  const HttpResponse head = parse_http_response(raw.substr(0, blank + 4));
  const auto length = head.headers.find("content-length");
  if (length == head.headers.end() || head.headers.count("transfer-encoding") != 0) return false;
  char* end = nullptr;
  const unsigned long long expected = std::strtoull(length->second.c_str(), &end, 10);
  if (end == length->second.c_str()) return false;
  return raw.size() - (blank + 4) >= expected;
}

// Decodes a chunked body; false when it is malformed or truncated.
bool dechunk(const std::string& in, std::string& out) {
  out.clear();
  std::size_t at = 0;
  for (;;) {
    const auto eol = in.find("\r\n", at);
    if (eol == std::string::npos) return false;
    char* end = nullptr;
    const std::string size_text = in.substr(at, eol - at);
    const unsigned long long size = std::strtoull(size_text.c_str(), &end, 16);
    if (end == size_text.c_str()) return false;
    at = eol + 2;
    if (size == 0) return true;  // trailers, if any, are ignored
    if (in.size() - at < size + 2) return false;
    out.append(in, at, static_cast<std::size_t>(size));
    at += static_cast<std::size_t>(size) + 2;
  }
}

}  // namespace

HttpResponse parse_http_response(const std::string& raw) {
  HttpResponse response;
  response.raw = raw;
  const auto blank = raw.find("\r\n\r\n");
  const std::string head = raw.substr(0, blank);
  std::size_t at = head.find("\r\n");
  const std::string status_line = head.substr(0, at);

  // "HTTP/1.x NNN reason"
  if (status_line.rfind("HTTP/", 0) != 0) return response;
  const auto space = status_line.find(' ');
  if (space == std::string::npos || status_line.size() < space + 4) return response;
  const std::string code = status_line.substr(space + 1, 3);
  if (!std::all_of(code.begin(), code.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) return response;
  if (status_line.size() > space + 4 && status_line[space + 4] != ' ') return response;
  response.status = std::atoi(code.c_str());

  // Header lines; one without a colon is skipped (this is a test client, not a validator).
  while (at != std::string::npos) {
    const auto next = head.find("\r\n", at + 2);
    const std::string line = head.substr(at + 2, next == std::string::npos ? std::string::npos : next - at - 2);
    at = next;
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string name = to_lower(trim(line.substr(0, colon)));
    const std::string value = trim(line.substr(colon + 1));
    auto [field, inserted] = response.headers.emplace(name, value);
    if (!inserted) field->second += ", " + value;
  }
  if (blank == std::string::npos) return response;

  // The body, cut or de-chunked as the head says.
  response.body = raw.substr(blank + 4);
  const auto encoding = response.headers.find("transfer-encoding");
  const auto length = response.headers.find("content-length");
  if (encoding != response.headers.end() && to_lower(encoding->second).find("chunked") != std::string::npos) {
    std::string decoded;
    if (dechunk(response.body, decoded)) response.body = std::move(decoded);
  } else if (length != response.headers.end()) {
    const unsigned long long expected = std::strtoull(length->second.c_str(), nullptr, 10);
    if (response.body.size() > expected) response.body.resize(static_cast<std::size_t>(expected));
  }
  return response;
}

HttpResponse http_request(int port, const std::string& raw_request, bool tls, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  const SigpipeGuard no_sigpipe;

  const int fd = connect_loopback(port, deadline);
  if (fd < 0) return {};
  SSL* ssl = nullptr;
  std::unique_ptr<SSL_CTX, SslContextFree> context;
  if (tls) {
    context = make_client_context();
    ssl = context ? SSL_new(context.get()) : nullptr;
    if (ssl == nullptr || SSL_set_fd(ssl, fd) != 1) {
      if (ssl != nullptr) SSL_free(ssl);
      ::close(fd);
      ERR_clear_error();
      return {};
    }
  }
  Stream stream(fd, ssl);  // owns fd and ssl from here
  if (!stream.handshake(deadline)) return {};

  // Write and read together until the response is complete, the server closes, or time runs out.
  const bool head_only = raw_request.rfind("HEAD ", 0) == 0;
  std::size_t written = 0;
  std::string received;
  char buffer[16 * 1024];
  while (Clock::now() < deadline) {
    bool progressed = false;
    if (written < raw_request.size()) {
      const long n = stream.write(raw_request.data() + written, raw_request.size() - written);
      if (n > 0) {
        written += static_cast<std::size_t>(n);
        progressed = true;
      } else if (n == Stream::kFailed) {
        written = raw_request.size();  // the server stopped listening; what it answered may still be read
      }
    }
    const long n = stream.read(buffer, sizeof buffer);
    if (n == 0 || n == Stream::kFailed) break;
    if (n > 0) {
      received.append(buffer, static_cast<std::size_t>(n));
      if (response_complete(received, head_only)) break;
      progressed = true;
    }
    if (progressed) continue;
    // Neither direction can move: wait for whichever may.
    short events = stream.read_events();
    if (written < raw_request.size()) events = static_cast<short>(events | stream.write_events());
    pollfd pfd{stream.fd(), events, 0};
    if (millis_left(deadline) == 0 || ::poll(&pfd, 1, millis_left(deadline)) <= 0) break;
  }
  return parse_http_response(received);
}

HttpResponse http_get(int port, const std::string& target,
                      const std::vector<std::pair<std::string, std::string>>& extra_headers, bool tls,
                      std::chrono::milliseconds timeout) {
  bool own_host = true;
  bool own_connection = true;
  std::string extra;
  for (const auto& [name, value] : extra_headers) {
    const std::string lower = to_lower(name);
    if (lower == "host") own_host = false;
    if (lower == "connection") own_connection = false;
    extra += name + ": " + value + "\r\n";
  }
  std::string request = "GET " + target + " HTTP/1.1\r\n";
  if (own_host) request += "Host: 127.0.0.1:" + std::to_string(port) + "\r\n";
  request += extra;
  if (own_connection) request += "Connection: close\r\n";
  request += "\r\n";
  return http_request(port, request, tls, timeout);
}

}  // namespace rfbsim::test::net
