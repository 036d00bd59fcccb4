// SPDX-License-Identifier: GPL-2.0-or-later
// The misbehaving clients and probes of abuse_clients.hpp: plain POSIX sockets, /proc and SQLite.
#include "abuse_clients.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sqlite3.h>
#include <sys/ioctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rfbsim::test::abuse {

namespace {

using SteadyClock = std::chrono::steady_clock;

// Sends all of `data` on a blocking socket; false when the peer is gone (no SIGPIPE).
bool send_all(int fd, const std::string& data) {
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return true;
}

// Waits until `fd` is readable or `deadline` passes; false on timeout.
bool wait_readable(int fd, SteadyClock::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SteadyClock::now()).count();
    if (left <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(left));
    if (ready > 0) return true;
    if (ready < 0 && errno != EINTR) return false;
  }
}

// Exactly `count` bytes straight from the socket, or an exception naming `what`.
std::string socket_exact(int fd, std::size_t count, SteadyClock::time_point deadline, const char* what) {
  std::string out;
  char buffer[4096];
  while (out.size() < count) {
    if (!wait_readable(fd, deadline)) throw std::runtime_error(std::string("timed out reading ") + what);
    const ssize_t n = ::recv(fd, buffer, std::min(sizeof buffer, count - out.size()), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("connection closed reading ") + what);
    out.append(buffer, static_cast<std::size_t>(n));
  }
  return out;
}

unsigned be16(const std::string& bytes, std::size_t at) {
  return (static_cast<unsigned char>(bytes[at]) << 8U) | static_cast<unsigned char>(bytes[at + 1]);
}

std::uint32_t be32(const std::string& bytes, std::size_t at) {
  return (static_cast<std::uint32_t>(be16(bytes, at)) << 16U) | be16(bytes, at + 2);
}

void put16(std::string& out, unsigned value) {
  out.push_back(static_cast<char>((value >> 8U) & 0xFFU));
  out.push_back(static_cast<char>(value & 0xFFU));
}

// The fields after the command name of /proc/PID/stat, from field 3 (state) on; empty when the process is gone.
std::vector<std::string> stat_fields(pid_t pid) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(file, line)) return {};
  // The command name may hold spaces and ')': the fields start after the last ')'.
  const std::size_t close = line.rfind(')');
  if (close == std::string::npos) return {};
  std::istringstream in(line.substr(close + 1));
  std::vector<std::string> fields;
  for (std::string field; in >> field;) fields.push_back(field);
  return fields;
}

}  // namespace

net::HttpResponse request_from(const std::string& source, int port, const std::string& raw_request,
                               std::chrono::milliseconds timeout) {
  const int fd = connect_from(source, port);
  if (fd < 0) return {};
  const auto deadline = SteadyClock::now() + timeout;
  std::string received;
  if (send_all(fd, raw_request)) {
    char buffer[8192];
    while (wait_readable(fd, deadline)) {
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      received.append(buffer, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return net::parse_http_response(received);
}

std::string raw_request(const std::string& method, const std::string& target, int port,
                        const std::vector<std::pair<std::string, std::string>>& headers) {
  std::string request = method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n";
  for (const auto& [name, value] : headers) request += name + ": " + value + "\r\n";
  return request + "Connection: close\r\n\r\n";
}

bool peer_closed(int fd) {
  // Whatever the server said before it closed (an error page) is read away, or it would hide the FIN.
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n > 0) continue;
    if (n == 0) return true;
    if (errno == EINTR) continue;
    return errno != EAGAIN && errno != EWOULDBLOCK;
  }
}

// ---------------------------------------------------------------------------------------------------------
// IdleConnections
// ---------------------------------------------------------------------------------------------------------

IdleConnections::IdleConnections(const std::string& source, int port, int count) {
  fds_.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const int fd = connect_from(source, port);
    if (fd < 0) {
      const std::string why = std::strerror(errno);
      close_all();
      throw std::runtime_error("idle connection " + std::to_string(i + 1) + " of " + std::to_string(count) +
                               " failed: " + why);
    }
    fds_.push_back(fd);
  }
}

IdleConnections::~IdleConnections() { close_all(); }

int IdleConnections::closed() const {
  return static_cast<int>(std::count_if(fds_.begin(), fds_.end(), [](int fd) { return peer_closed(fd); }));
}

void IdleConnections::close_all() {
  for (const int fd : fds_) ::close(fd);
  fds_.clear();
}

// ---------------------------------------------------------------------------------------------------------
// SlowHeaderClients
// ---------------------------------------------------------------------------------------------------------

SlowHeaderClients::SlowHeaderClients(const std::string& source, int port, int count,
                                     std::chrono::milliseconds interval) {
  for (int i = 0; i < count; ++i) {
    const int fd = connect_from(source, port);
    if (fd < 0) {
      const std::string why = std::strerror(errno);
      for (const int open : fds_) ::close(open);
      throw std::runtime_error("slow connection " + std::to_string(i + 1) + " failed: " + why);
    }
    // The request line and the Host line at once, as a browser would start; the rest never comes.
    send_all(fd, "GET /start?uid=slow-" + std::to_string(i) + " HTTP/1.1\r\nHost: 127.0.0.1\r\n");
    fds_.push_back(fd);
  }
  done_.assign(fds_.size(), false);
  opened_ = SteadyClock::now();
  thread_ = std::thread([this, interval] { trickle(interval); });
}

SlowHeaderClients::~SlowHeaderClients() {
  stop_ = true;
  thread_.join();
  for (const int fd : fds_) ::close(fd);
}

std::chrono::milliseconds SlowHeaderClients::longest_open() const {
  return std::chrono::milliseconds(longest_open_ms_.load());
}

void SlowHeaderClients::trickle(std::chrono::milliseconds interval) {
  int line = 0;
  auto next_line = SteadyClock::now() + interval;
  while (!stop_ && closed_.load() < static_cast<int>(fds_.size())) {
    // Look for closes often, so that how long each stayed open is known to a few tens of milliseconds.
    for (std::size_t i = 0; i < fds_.size(); ++i) {
      if (done_[i] || !peer_closed(fds_[i])) continue;
      done_[i] = true;
      const auto open_ms =
          std::chrono::duration_cast<std::chrono::milliseconds>(SteadyClock::now() - opened_).count();
      longest_open_ms_ = std::max<long long>(longest_open_ms_.load(), open_ms);
      ++closed_;
    }
    if (SteadyClock::now() >= next_line) {
      next_line += interval;
      ++line;
      for (std::size_t i = 0; i < fds_.size(); ++i) {
        if (!done_[i] && send_all(fds_[i], "X-Slow-" + std::to_string(line) + ": still typing\r\n")) ++lines_sent_;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// ---------------------------------------------------------------------------------------------------------
// RawWsRfbClient
// ---------------------------------------------------------------------------------------------------------

RawWsRfbClient::RawWsRfbClient(const std::string& source, int port, const std::string& target,
                               const std::string& origin) {
  // A small receive buffer, so that what the client does not read backs up into the server soon.
  fd_ = connect_from(source, port, 4096);
  if (fd_ < 0) throw std::runtime_error(std::string("cannot connect: ") + std::strerror(errno));
  if (!send_all(fd_, upgrade_request(target, port, origin))) throw std::runtime_error("cannot send the handshake");
  // The head byte by byte: nothing of the WebSocket stream after it is taken by mistake.
  const auto deadline = SteadyClock::now() + std::chrono::seconds(10);
  std::string head;
  while (head.size() < 4 || head.compare(head.size() - 4, 4, "\r\n\r\n") != 0) {
    head += socket_exact(fd_, 1, deadline, "the handshake answer");
    if (head.size() > 8192) throw std::runtime_error("handshake answer too long");
  }
  if (head.rfind("HTTP/1.1 101", 0) != 0) throw std::runtime_error("handshake refused: " + head.substr(0, 40));

  // RFB 3.8: version, security None, shared ClientInit, ServerInit.
  constexpr auto kStep = std::chrono::seconds(20);
  if (read_exact(12, kStep).rfind("RFB 003.00", 0) != 0) throw std::runtime_error("not an RFB server");
  send_binary("RFB 003.008\n");
  const auto type_count = static_cast<unsigned char>(read_exact(1, kStep)[0]);
  if (type_count == 0) throw std::runtime_error("the server refused the connection");
  const std::string types = read_exact(type_count, kStep);
  if (types.find('\x01') == std::string::npos) throw std::runtime_error("no security type None");
  send_binary(std::string(1, '\x01'));
  if (be32(read_exact(4, kStep), 0) != 0) throw std::runtime_error("security handshake failed");
  send_binary(std::string(1, '\x01'));
  const std::string init = read_exact(24, kStep);
  width_ = static_cast<int>(be16(init, 0));
  height_ = static_cast<int>(be16(init, 2));
  read_exact(be32(init, 20), kStep);  // the desktop name
}

RawWsRfbClient::~RawWsRfbClient() {
  if (fd_ >= 0) ::close(fd_);
}

void RawWsRfbClient::set_raw_encoding() {
  std::string message = {'\x02', '\x00'};
  put16(message, 1);
  message.append(4, '\x00');  // encoding 0: Raw
  send_binary(message);
}

void RawWsRfbClient::request_full_update() {
  std::string message = {'\x03', '\x00'};  // incremental = 0: the whole picture, every time
  put16(message, 0);
  put16(message, 0);
  put16(message, static_cast<unsigned>(width_));
  put16(message, static_cast<unsigned>(height_));
  send_binary(message);
}

int RawWsRfbClient::unread_bytes() const {
  int bytes = 0;
  return ::ioctl(fd_, FIONREAD, &bytes) == 0 ? bytes : -1;
}

void RawWsRfbClient::send_binary(const std::string& payload) {
  // A client's frames are masked (RFC 6455 5.3); the key need not be secret here.
  const unsigned char mask[4] = {0x37, 0xfa, 0x21, 0x3d};
  std::string frame;
  frame.push_back(static_cast<char>(0x82));  // FIN, binary
  if (payload.size() < 126) {
    frame.push_back(static_cast<char>(0x80U | payload.size()));
  } else {
    frame.push_back(static_cast<char>(0x80U | 126U));
    put16(frame, static_cast<unsigned>(payload.size()));
  }
  frame.append(reinterpret_cast<const char*>(mask), 4);
  for (std::size_t i = 0; i < payload.size(); ++i) frame.push_back(static_cast<char>(payload[i] ^ mask[i % 4]));
  if (!send_all(fd_, frame)) throw std::runtime_error("the server closed the WebSocket");
}

std::string RawWsRfbClient::read_exact(std::size_t count, std::chrono::milliseconds timeout) {
  const auto deadline = SteadyClock::now() + timeout;
  while (received_.size() < count) read_frame(deadline);
  std::string out = received_.substr(0, count);
  received_.erase(0, count);
  return out;
}

void RawWsRfbClient::read_frame(SteadyClock::time_point deadline) {
  const std::string head = socket_exact(fd_, 2, deadline, "a frame head");
  const unsigned opcode = static_cast<unsigned char>(head[0]) & 0x0FU;
  std::uint64_t length = static_cast<unsigned char>(head[1]) & 0x7FU;
  if (length == 126) {
    length = be16(socket_exact(fd_, 2, deadline, "a frame length"), 0);
  } else if (length == 127) {
    const std::string bytes = socket_exact(fd_, 8, deadline, "a frame length");
    length = (static_cast<std::uint64_t>(be32(bytes, 0)) << 32U) | be32(bytes, 4);
  }
  if (length > (std::uint64_t{64} << 20)) throw std::runtime_error("frame too long");
  const std::string payload = socket_exact(fd_, static_cast<std::size_t>(length), deadline, "a frame");
  switch (opcode) {
    case 0x0:
    case 0x2: received_ += payload; return;
    case 0x8:
      throw std::runtime_error("the server closed the WebSocket" +
                               (payload.size() >= 2 ? " with code " + std::to_string(be16(payload, 0)) : ""));
    default: return;  // ping, pong, text: not part of the RFB stream
  }
}

// ---------------------------------------------------------------------------------------------------------
// Probes
// ---------------------------------------------------------------------------------------------------------

double process_cpu_seconds(pid_t pid) {
  const std::vector<std::string> fields = stat_fields(pid);
  // utime and stime are fields 14 and 15 of the line, 12 and 13 counted from field 3.
  if (fields.size() < 13) return -1;
  const double ticks = std::stod(fields[11]) + std::stod(fields[12]);
  return ticks / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

long resident_kib(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

std::string index_column(const std::filesystem::path& data_dir, const std::string& token, const std::string& column) {
  sqlite3* db = nullptr;
  const std::string path = (data_dir / "sessions.db").string();
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    throw std::runtime_error("cannot open " + path);
  }
  sqlite3_busy_timeout(db, 5000);  // the manager writes while we read
  sqlite3_stmt* stmt = nullptr;
  // `column` comes from the test's own literals, never from outside.
  const std::string sql = "SELECT " + column + " FROM sessions WHERE token = ?";
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
    const std::string message = sqlite3_errmsg(db);
    sqlite3_close(db);
    throw std::runtime_error("index query failed: " + message);
  }
  sqlite3_bind_text(stmt, 1, token.c_str(), -1, SQLITE_TRANSIENT);
  std::string value;
  if (sqlite3_step(stmt) == SQLITE_ROW) {
    const auto* text = sqlite3_column_text(stmt, 0);
    if (text != nullptr) value = reinterpret_cast<const char*>(text);
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return value;
}

LowDescriptorReserve::LowDescriptorReserve(int count) {
  for (int i = 0; i < count; ++i) {
    const int fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (fd < 0) break;
    fds_.push_back(fd);
  }
}

LowDescriptorReserve::~LowDescriptorReserve() { release(); }

void LowDescriptorReserve::release() {
  for (const int fd : fds_) ::close(fd);
  fds_.clear();
}

bool raise_descriptor_limit(std::uint64_t wanted) {
  rlimit limit{};
  if (::getrlimit(RLIMIT_NOFILE, &limit) != 0) return false;
  if (limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur >= wanted) return true;
  if (limit.rlim_max != RLIM_INFINITY && limit.rlim_max < wanted) return false;
  limit.rlim_cur = static_cast<rlim_t>(wanted);
  return ::setrlimit(RLIMIT_NOFILE, &limit) == 0;
}

}  // namespace rfbsim::test::abuse
