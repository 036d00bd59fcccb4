// SPDX-License-Identifier: GPL-2.0-or-later
// RegistryServer: this host's Paxos acceptor of the uid registry (manager/cluster/uid_registry.hpp), on a port of its own.
//
// Each connection carries one signed request line (prepare or accept) and gets one signed answer (promise,
// accepted or reject). The acceptor's new state is committed to the index (table uid_acceptors) before the
// answer leaves, so that a crash can never make this host break a promise or forget a value. The SQLite
// writes run on a thread of their own with their own connection (a commit with synchronous=FULL waits for the
// disk, and the I/O thread carries every relay); the sockets, their timeouts and every callback run on the
// manager's I/O thread.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/thread_pool.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "sessions/session_index.hpp"
#include "cluster/uid_registry.hpp"

namespace rfbsim::manager {

class RegistryServer {
 public:
  /// The acceptor's answer, nothing when the index could not record its state. Called on the I/O thread.
  using Answered = std::function<void(const std::optional<RegistryMessage>& answer)>;

  /// Acceptor `self` among `peers`: listens on `bind_address`:`port` (0: any free port), verifies lines with
  /// `key` (registry_key) and keeps its state in the index at `index_path` through its own connection.
  /// Throws std::runtime_error naming the cause (address in use, index).
  RegistryServer(boost::asio::io_context& io, const std::string& bind_address, int port, std::string key,
                 std::string self, std::vector<ClusterPeer> peers, const std::string& index_path);
  /// Writes what is queued, then closes.
  ~RegistryServer();
  RegistryServer(const RegistryServer&) = delete;
  RegistryServer& operator=(const RegistryServer&) = delete;

  /// The port bound.
  [[nodiscard]] int port() const { return port_; }
  /// The highest ballot counter this acceptor had promised when it started (0: none).
  [[nodiscard]] std::uint64_t initial_counter() const { return initial_counter_; }
  /// Answers `request` (a prepare or accept addressed to this acceptor; this host's own proposals come here
  /// without a socket); `done` gets the answer once the state it depends on is committed.
  void handle(const RegistryMessage& request, Answered done);
  /// Stops accepting; connections in progress end by themselves within the read timeout.
  void stop();

 private:
  struct Connection;
  void accept();
  void serve(boost::asio::ip::tcp::socket socket);
  void answer(const std::shared_ptr<Connection>& connection, std::string line);

  boost::asio::io_context& io_;
  std::string key_;
  std::string self_;
  std::vector<ClusterPeer> peers_;
  SessionIndex store_;  // used on pool_'s thread only
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer accept_pause_;  // after a failed accept (EMFILE): a pause, not a spin
  int port_ = 0;
  std::uint64_t initial_counter_ = 0;
  std::shared_ptr<int> open_ = std::make_shared<int>(0);  // connections now; shared with them, which may outlive us
  boost::asio::thread_pool pool_{1};  // last: its thread uses store_
};

/// The cluster's shared secret from `path`, without trailing whitespace. Throws std::runtime_error if the file
/// cannot be read or holds fewer than 16 bytes; warns on stderr if other users may read it.
std::string read_cluster_secret(const std::string& path);

}  // namespace rfbsim::manager
