// SPDX-License-Identifier: GPL-2.0-or-later
// RegistryServer: this host's acceptor of the uid registry (manager/uid_registry.hpp), on a port of its own.
//
// Each connection carries one signed claim line and gets one answer: the home this host records for the uid,
// the claimed one if it had none. The record is committed to the index (table uid_homes) before the answer
// leaves, so that a crash can never make this host answer two different homes for one uid. The SQLite
// writes run on a thread of their own with their own connection (a commit with synchronous=FULL waits for the
// disk, and the I/O thread carries every relay); the sockets, their timeouts and every callback run on the
// manager's I/O thread.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/thread_pool.hpp>
#include <functional>
#include <memory>
#include <string>

#include "session_index.hpp"

namespace rfbsim::manager {

class RegistryServer {
 public:
  /// The home recorded for a uid, "" when the index could not record it. Called on the I/O thread.
  using Recorded = std::function<void(const std::string& home)>;

  /// Listens on `bind_address`:`port` (0: any free port) and records homes in the index at `index_path`
  /// through its own connection. Throws std::runtime_error naming the cause (address in use, index).
  RegistryServer(boost::asio::io_context& io, const std::string& bind_address, int port, std::string secret,
                 const std::string& index_path);
  /// Writes what is queued, then closes.
  ~RegistryServer();
  RegistryServer(const RegistryServer&) = delete;
  RegistryServer& operator=(const RegistryServer&) = delete;

  /// The port bound.
  [[nodiscard]] int port() const { return port_; }
  /// Records `host` as `uid`'s home unless it has one (this host's own claims come here without a socket);
  /// `done` gets the home recorded, once it is committed.
  void record(const std::string& uid, const std::string& host, Recorded done);
  /// Stops accepting; connections in progress end by themselves within the read timeout.
  void stop();

 private:
  struct Connection;
  void accept();
  void serve(boost::asio::ip::tcp::socket socket);
  void answer(const std::shared_ptr<Connection>& connection, std::string line);

  boost::asio::io_context& io_;
  std::string secret_;
  SessionIndex store_;  // used on pool_'s thread only
  boost::asio::ip::tcp::acceptor acceptor_;
  int port_ = 0;
  std::shared_ptr<int> open_ = std::make_shared<int>(0);  // connections now; shared with them, which may outlive us
  boost::asio::thread_pool pool_{1};  // last: its thread uses store_
};

/// The cluster's shared secret from `path`, without trailing whitespace. Throws std::runtime_error if the file
/// cannot be read or holds fewer than 16 bytes; warns on stderr if other users may read it.
std::string read_cluster_secret(const std::string& path);

}  // namespace rfbsim::manager
