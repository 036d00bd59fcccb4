// SPDX-License-Identifier: GPL-2.0-or-later
// RegistryClient: the claimer's side of the uid registry (manager/uid_registry.hpp). A claim round asks the
// peers one at a time, in the uid's rendezvous order, each with a timeout of its own; this host's acceptor is
// asked in-process at its place in the order. Asynchronous on the manager's I/O thread: nothing blocks, and
// the result comes back on that thread.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config.hpp"
#include "registry_server.hpp"

namespace rfbsim::manager {

class RegistryClient {
 public:
  /// The uid's decided home, or nothing when too few peers answered to decide (retry later).
  using Decided = std::function<void(const std::optional<std::string>& home)>;

  /// Claims for `self` among `peers` (this host included), signing with `secret`; `own` is this host's
  /// acceptor, which must outlive this object. `peer_timeout`: how long one peer may take to answer.
  RegistryClient(boost::asio::io_context& io, std::vector<ClusterPeer> peers, std::string self, std::string secret,
                 RegistryServer& own, std::chrono::milliseconds peer_timeout = std::chrono::seconds(1));
  ~RegistryClient();
  RegistryClient(const RegistryClient&) = delete;
  RegistryClient& operator=(const RegistryClient&) = delete;

  /// Runs a claim round for `uid` proposing this host; `done` is called once, on the I/O thread.
  void claim(const std::string& uid, Decided done);
  /// This host's id.
  [[nodiscard]] const std::string& self() const { return self_; }

 private:
  struct Round;
  void ask_next(const std::shared_ptr<Round>& round);
  // A remote peer's exchange, step by step: resolve (ask_peer), connect and send, read the owner line.
  void ask_peer(const std::shared_ptr<Round>& round, const ClusterPeer& peer);
  void send_claim(const std::shared_ptr<Round>& round,
                  const boost::asio::ip::tcp::resolver::results_type& endpoints);
  void read_answer(const std::shared_ptr<Round>& round);
  // The peer of the round's current attempt answered `home` (nothing: it did not, or not validly).
  void peer_done(const std::shared_ptr<Round>& round, const std::optional<std::string>& home);

  boost::asio::io_context& io_;
  std::vector<ClusterPeer> peers_;
  std::string self_;
  std::string secret_;
  RegistryServer& own_;
  std::chrono::milliseconds peer_timeout_;
};

}  // namespace rfbsim::manager
