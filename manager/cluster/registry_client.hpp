// SPDX-License-Identifier: GPL-2.0-or-later
// RegistryClient: the proposer's side of the uid registry (manager/cluster/uid_registry.hpp). A claim runs Paxos for
// the uid: phase 1 (prepare) and phase 2 (accept) each go to every peer at once, with one timeout per phase;
// this host's acceptor is asked in-process. A ballot that is refused or gets too few answers is retried with
// a higher one after a short random pause, a few times, then the claim is undecided. A learn-only round
// (learn) is the same Paxos round for a host that may not become the home (full, draining): it never
// proposes itself, so it runs phase 2 only to confirm a value some promise reported. Asynchronous on the
// manager's I/O thread: nothing blocks (peer names are resolved in the background, never during a claim),
// and the result comes back on that thread.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "cluster/registry_server.hpp"
#include "cluster/uid_registry.hpp"

namespace rfbsim::manager {

class RegistryClient {
 public:
  /// The uid's decided home, or nothing when no ballot reached a majority (retry later).
  using Decided = std::function<void(const std::optional<std::string>& home)>;
  /// What a learn-only round found out.
  using Learned = std::function<void(const LearnResult& result)>;

  /// Proposes for `self` among `peers` (this host included), signing with `key` (registry_key); `own` is
  /// this host's acceptor, which must outlive this object. `phase_timeout`: how long one phase waits for
  /// answers. Starts resolving the peers' names at once, in the background.
  RegistryClient(boost::asio::io_context& io, std::vector<ClusterPeer> peers, std::string self, std::string key,
                 RegistryServer& own, std::chrono::milliseconds phase_timeout = std::chrono::seconds(1));
  ~RegistryClient();
  RegistryClient(const RegistryClient&) = delete;
  RegistryClient& operator=(const RegistryClient&) = delete;

  /// Decides `uid`'s home (this host unless a value was accepted before); `done` is called once, on the I/O
  /// thread.
  void claim(const std::string& uid, Decided done);
  /// Learns `uid`'s home without proposing this host: after phase 1, phase 2 runs only with a value some
  /// promise reported accepted (Paxos trusts a value only once a majority accepted it at one ballot); when
  /// none did, the result is kUnknown and nothing is accepted anywhere. `done` is called once, on the I/O
  /// thread.
  void learn(const std::string& uid, Learned done);
  /// This host's id.
  [[nodiscard]] const std::string& self() const { return self_; }

 private:
  struct Remote;    // a peer's address and what its name resolved to
  struct Round;     // one claim or learn-only round: up to kAttempts ballots
  struct Phase;     // one phase of one ballot: a request to every peer, answers until the outcome is known
  struct Exchange;  // one peer's connection in a phase
  void resolve(const std::shared_ptr<Remote>& remote);
  void run_ballot(const std::shared_ptr<Round>& round);
  void run_phase(const std::shared_ptr<Round>& round, MessageKind kind);
  void ask(const std::shared_ptr<Phase>& phase, const std::shared_ptr<Remote>& remote);
  // An acceptor's answer (nothing: none, or one that did not verify) reaches the phase's tally.
  void answered(const std::shared_ptr<Phase>& phase, const std::string& acceptor,
                const std::optional<RegistryMessage>& answer);
  void settle(const std::shared_ptr<Phase>& phase);
  void retry_or_give_up(const std::shared_ptr<Round>& round);

  boost::asio::io_context& io_;
  std::vector<ClusterPeer> peers_;
  std::vector<std::string> ids_;
  std::vector<std::shared_ptr<Remote>> remotes_;  // every peer but this host
  std::string self_;
  std::string key_;
  RegistryServer& own_;
  std::chrono::milliseconds phase_timeout_;
  std::uint64_t counter_ = 0;  // the last ballot counter used or seen: the next ballot goes above it
  std::mt19937 random_{std::random_device{}()};
};

}  // namespace rfbsim::manager
