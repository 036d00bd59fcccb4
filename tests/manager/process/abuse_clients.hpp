// SPDX-License-Identifier: GPL-2.0-or-later
// Misbehaving clients for sim_manager's load and fault tests: requests from a chosen loopback address, idle
// and slowly trickling connections, a raw WebSocket RFB client that stops reading, and /proc and index probes.
//
// Linux routes all of 127.0.0.0/8 to loopback, so a socket bound to 127.0.0.2 before connect() reaches the
// manager on 127.0.0.1 as "another address": the per-address limits can be tested on one machine.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "http_client.hpp"
#include "scoped_env.hpp"
#include "source_address.hpp"

namespace rfbsim::test::abuse {

// A socket from a chosen loopback address, and a WebSocket handshake (tests/support/source_address.hpp).
using rfbsim::test::connect_from;
using rfbsim::test::upgrade_request;

/// Sends `raw_request` from `source` and reads until the server closes or `timeout` passes; parsed as
/// net::http_request does (status -1 when nothing parseable came back).
net::HttpResponse request_from(const std::string& source, int port, const std::string& raw_request,
                               std::chrono::milliseconds timeout = std::chrono::seconds(5));

/// A `method target HTTP/1.1` request for 127.0.0.1:`port` with `headers` and Connection: close.
std::string raw_request(const std::string& method, const std::string& target, int port,
                        const std::vector<std::pair<std::string, std::string>>& headers = {});

/// Whether the server has closed this socket (FIN or RST seen); never blocks. Reads away (and drops) whatever
/// the server sent before, which would otherwise hide its FIN.
bool peer_closed(int fd);

/// Connections that connect and then send nothing, as a flood of half-open HTTP requests does.
class IdleConnections {
 public:
  /// Opens `count` connections from `source` to 127.0.0.1:`port`. Throws std::runtime_error when a connect
  /// fails (the message says how many got through first).
  IdleConnections(const std::string& source, int port, int count);
  /// Closes every connection.
  ~IdleConnections();
  IdleConnections(const IdleConnections&) = delete;
  IdleConnections& operator=(const IdleConnections&) = delete;

  /// How many the server has closed so far.
  [[nodiscard]] int closed() const;
  /// How many were opened.
  [[nodiscard]] int size() const { return static_cast<int>(fds_.size()); }
  /// Closes every connection now.
  void close_all();

 private:
  std::vector<int> fds_;
};

/// Slowloris: connections that each start a GET and then send one more header line every `interval`, never
/// finishing the head, until the server closes them. Runs on its own thread.
class SlowHeaderClients {
 public:
  /// Opens `count` connections from `source` and starts trickling. Throws std::runtime_error when a connect
  /// fails.
  SlowHeaderClients(const std::string& source, int port, int count,
                    std::chrono::milliseconds interval = std::chrono::seconds(1));
  /// Stops the thread and closes what is still open.
  ~SlowHeaderClients();
  SlowHeaderClients(const SlowHeaderClients&) = delete;
  SlowHeaderClients& operator=(const SlowHeaderClients&) = delete;

  /// How many the server has closed so far.
  [[nodiscard]] int closed() const { return closed_.load(); }
  /// Header lines sent so far, after the request lines.
  [[nodiscard]] int lines_sent() const { return lines_sent_.load(); }
  /// The longest time a connection stayed open before the server closed it (zero before any closed).
  [[nodiscard]] std::chrono::milliseconds longest_open() const;

 private:
  void trickle(std::chrono::milliseconds interval);

  std::vector<int> fds_;
  std::vector<bool> done_;
  std::chrono::steady_clock::time_point opened_;
  std::atomic<int> closed_{0};
  std::atomic<int> lines_sent_{0};
  std::atomic<long long> longest_open_ms_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// A browser that speaks RFB over a raw WebSocket (masked frames, no library), so that a test decides exactly
/// when it reads: the way to be a slow reader.
class RawWsRfbClient {
 public:
  /// Connects from `source` with a small receive buffer, opens the WebSocket at `target` with `origin`, and
  /// completes the RFB handshake (security None, shared). Throws std::runtime_error on any failure.
  RawWsRfbClient(const std::string& source, int port, const std::string& target, const std::string& origin);
  ~RawWsRfbClient();
  RawWsRfbClient(const RawWsRfbClient&) = delete;
  RawWsRfbClient& operator=(const RawWsRfbClient&) = delete;

  /// Asks for the Raw encoding only: the largest pictures, 4 bytes a pixel.
  void set_raw_encoding();
  /// Sends a non-incremental FramebufferUpdateRequest for the whole screen; reads nothing.
  void request_full_update();
  /// Bytes the kernel holds for us unread (FIONREAD).
  [[nodiscard]] int unread_bytes() const;
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }

 private:
  void send_binary(const std::string& payload);
  std::string read_exact(std::size_t count, std::chrono::milliseconds timeout);
  void read_frame(std::chrono::steady_clock::time_point deadline);

  int fd_ = -1;
  std::string received_;  // WebSocket payload bytes not yet consumed
  int width_ = 0;
  int height_ = 0;
};

/// User plus system CPU time the process has used, seconds (/proc/PID/stat); -1 when it is gone.
double process_cpu_seconds(pid_t pid);

/// The process's resident set size, KiB (VmRSS in /proc/PID/status); -1 when it is gone.
long resident_kib(pid_t pid);

/// One text column of the index row of session `token` in `data_dir`/sessions.db ("" for NULL or no row).
std::string index_column(const std::filesystem::path& data_dir, const std::string& token, const std::string& column);

/// The shared ScopedEnv (tests/support/scoped_env.hpp), under this file's namespace as the tests use it.
using rfbsim::test::ScopedEnv;

/// Low descriptor numbers held free for later: libvncclient waits with select(), which aborts on a descriptor
/// at or above FD_SETSIZE (1024), so a test that opens thousands of sockets keeps some low ones for its client.
class LowDescriptorReserve {
 public:
  /// Takes `count` of the lowest free descriptors (on /dev/null).
  explicit LowDescriptorReserve(int count);
  /// Releases what is still held.
  ~LowDescriptorReserve();
  LowDescriptorReserve(const LowDescriptorReserve&) = delete;
  LowDescriptorReserve& operator=(const LowDescriptorReserve&) = delete;
  /// Frees the descriptors now, for the next sockets to take.
  void release();

 private:
  std::vector<int> fds_;
};

/// Raises this process's soft RLIMIT_NOFILE to at least `wanted` (within the hard limit); whether it now is.
bool raise_descriptor_limit(std::uint64_t wanted);

}  // namespace rfbsim::test::abuse
