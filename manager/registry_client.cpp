// SPDX-License-Identifier: GPL-2.0-or-later
// A claim round: resolve, connect, send the claim, read the owner line; one peer after another.
#include "registry_client.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/write.hpp>
#include <cstdio>

#include "uid_registry.hpp"

namespace rfbsim::manager {

namespace {

namespace asio = boost::asio;
using asio::ip::tcp;

long long unix_now() {
  return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

struct RegistryClient::Round {
  Round(asio::io_context& io, std::string uid_, std::vector<ClusterPeer> order_, const std::string& self,
        Decided done_)
      : uid(std::move(uid_)),
        order(std::move(order_)),
        tally(self, static_cast<int>(order.size())),
        done(std::move(done_)),
        resolver(io),
        socket(io),
        timer(io) {}
  std::string uid;
  std::vector<ClusterPeer> order;  // the uid's rendezvous order
  std::size_t next = 0;            // the next peer to ask
  ClaimTally tally;
  Decided done;
  int answers = 0;  // for the log of an undecided round
  // The current peer's exchange. `attempt` tells a late timer of an earlier peer from the current one;
  // `expired`: the current peer's time is up, whatever step it is in.
  tcp::resolver resolver;
  tcp::socket socket;
  asio::steady_timer timer;
  asio::streambuf buffer{kMaxRegistryLine};
  std::string request;
  std::string peer;  // the current peer's id, for the log
  unsigned attempt = 0;
  bool expired = false;
};

RegistryClient::RegistryClient(asio::io_context& io, std::vector<ClusterPeer> peers, std::string self,
                               std::string secret, RegistryServer& own, std::chrono::milliseconds peer_timeout)
    : io_(io),
      peers_(std::move(peers)),
      self_(std::move(self)),
      secret_(std::move(secret)),
      own_(own),
      peer_timeout_(peer_timeout) {}

RegistryClient::~RegistryClient() = default;

void RegistryClient::claim(const std::string& uid, Decided done) {
  auto round = std::make_shared<Round>(io_, uid, rendezvous_order(uid, peers_), self_, std::move(done));
  ask_next(round);
}

void RegistryClient::ask_next(const std::shared_ptr<Round>& round) {
  // Decided as soon as a majority agrees: the rest need not be asked.
  if (const auto home = round->tally.decided()) {
    round->done(home);
    return;
  }
  if (round->next == round->order.size()) {
    std::fprintf(stderr, "[registry] uid %s: no home decided (%d of %zu peers answered); the participant retries\n",
                 round->uid.c_str(), round->answers, round->order.size());
    round->done(std::nullopt);
    return;
  }
  const ClusterPeer& peer = round->order[round->next++];
  if (peer.id == self_) {
    own_.record(round->uid, round->tally.proposal(), [this, round](const std::string& home) {
      peer_done(round, home.empty() ? std::nullopt : std::optional<std::string>(home));
    });
    return;
  }
  ask_peer(round, peer);
}

void RegistryClient::ask_peer(const std::shared_ptr<Round>& round, const ClusterPeer& peer) {
  const unsigned attempt = ++round->attempt;
  round->expired = false;
  round->buffer.consume(round->buffer.size());
  round->request = claim_line(secret_, round->uid, round->tally.proposal(), unix_now());
  round->timer.expires_after(peer_timeout_);
  round->timer.async_wait([round, attempt](const boost::system::error_code& ec) {
    if (ec || round->attempt != attempt) return;
    // Cancels whichever step is pending; a step that completes anyway sees `expired` and gives up.
    round->expired = true;
    round->resolver.cancel();
    boost::system::error_code ignored;
    round->socket.close(ignored);
  });
  round->peer = peer.id;
  round->resolver.async_resolve(
      peer.address, std::to_string(peer.port),
      [this, round](const boost::system::error_code& ec, const tcp::resolver::results_type& endpoints) {
        if (ec || round->expired) return peer_done(round, std::nullopt);
        send_claim(round, endpoints);
      });
}

void RegistryClient::send_claim(const std::shared_ptr<Round>& round, const tcp::resolver::results_type& endpoints) {
  auto connected = [this, round](const boost::system::error_code& ec, const tcp::endpoint&) {
    if (ec || round->expired) return peer_done(round, std::nullopt);
    asio::async_write(round->socket, asio::buffer(round->request),
                      [this, round](const boost::system::error_code& ec, std::size_t) {
                        if (ec || round->expired) return peer_done(round, std::nullopt);
                        read_answer(round);
                      });
  };
  asio::async_connect(round->socket, endpoints, connected);
}

void RegistryClient::read_answer(const std::shared_ptr<Round>& round) {
  auto answered = [this, round](const boost::system::error_code& ec, std::size_t length) {
    if (ec || round->expired) return peer_done(round, std::nullopt);
    const auto data = round->buffer.data();
    const std::string line(asio::buffers_begin(data), asio::buffers_begin(data) + static_cast<long>(length) - 1);
    const auto home = parse_owner_line(line, secret_, round->uid);
    // A wrong answer is no vote: a peer with another secret, or not a registry at all.
    if (!home) {
      std::fprintf(stderr, "[registry] peer %s answered '%.80s'; not counted\n", round->peer.c_str(), line.c_str());
    }
    peer_done(round, home);
  };
  asio::async_read_until(round->socket, round->buffer, '\n', answered);
}

void RegistryClient::peer_done(const std::shared_ptr<Round>& round, const std::optional<std::string>& home) {
  round->timer.cancel();
  boost::system::error_code ignored;
  round->socket.close(ignored);
  if (home) {
    ++round->answers;
    round->tally.answered(*home);
  }
  ask_next(round);
}

}  // namespace rfbsim::manager
