// SPDX-License-Identifier: GPL-2.0-or-later
// A claim or a learn-only round: ballots of two phases each, every peer asked at once; peer names resolved in
// the background.
#include "cluster/registry_client.hpp"

#include <boost/asio/post.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/write.hpp>
#include <cstdio>

#include "admission/tokens.hpp"
#include "admission/unix_time.hpp"
#include "rfbsim/log.hpp"

namespace rfbsim::manager {

namespace {

namespace asio = boost::asio;
using asio::ip::tcp;

// A claim tries this many ballots (the first and three retries) before it gives up for now.
constexpr int kAttempts = 4;
// The pause before a retry, drawn anew each time: duelling proposers drift apart instead of colliding again.
constexpr int kRetryPauseMinMs = 20;
constexpr int kRetryPauseMaxMs = 150;
// A peer name that does not resolve is tried again this often; one that resolved is looked up again after a
// failed connection, at most this often (a restarted host may have a new address).
constexpr auto kResolveRetry = std::chrono::seconds(2);
constexpr auto kResolveRefresh = std::chrono::seconds(5);

}  // namespace

struct RegistryClient::Remote {
  Remote(asio::io_context& io, ClusterPeer p) : peer(std::move(p)), resolver(io), retry(io) {}
  ClusterPeer peer;
  std::optional<tcp::endpoint> endpoint;  // nothing until the name resolved: the peer counts as down
  bool numeric = false;                   // a numeric address: never looked up
  bool resolving = false;
  bool warned = false;  // the failure to resolve was logged (once per failing streak)
  std::chrono::steady_clock::time_point last_lookup{};
  tcp::resolver resolver;
  asio::steady_timer retry;
};

struct RegistryClient::Round {
  Round(asio::io_context& io, std::string uid_, bool learn_only_, Learned done_)
      : uid(std::move(uid_)), learn_only(learn_only_), done(std::move(done_)), pause(io) {}
  std::string uid;
  bool learn_only;  // never propose this host: confirm a value a promise reported, or end kUnknown
  Learned done;
  std::string proposal;      // what the current ballot's phase 2 proposes
  asio::steady_timer pause;  // before a retry
  int attempt = 0;           // ballots tried so far
  Ballot ballot;             // the current ballot
  std::string nonce;         // drawn for the current ballot: answers must echo it
  std::optional<BallotTally> tally;
};

struct RegistryClient::Exchange {
  explicit Exchange(asio::io_context& io) : socket(io) {}
  tcp::socket socket;
  asio::streambuf buffer{kMaxRegistryLine};
  RegistryMessage request;  // what this acceptor was asked: its answer must echo it
  std::string line;
};

struct RegistryClient::Phase {
  Phase(asio::io_context& io, std::shared_ptr<Round> r) : round(std::move(r)), timer(io) {}
  std::shared_ptr<Round> round;
  RegistryMessage request;  // the request every acceptor gets, but for its acceptor field
  asio::steady_timer timer;
  std::vector<std::shared_ptr<Exchange>> exchanges;
  bool settled = false;  // the outcome is known: late answers and timers change nothing
};

RegistryClient::RegistryClient(asio::io_context& io, std::vector<ClusterPeer> peers, std::string self, std::string key,
                               RegistryServer& own, std::chrono::milliseconds phase_timeout)
    : io_(io),
      peers_(std::move(peers)),
      self_(std::move(self)),
      key_(std::move(key)),
      own_(own),
      phase_timeout_(phase_timeout),
      counter_(own.initial_counter()) {
  for (const ClusterPeer& peer : peers_) {
    ids_.push_back(peer.id);
    if (peer.id == self_) continue;
    auto remote = std::make_shared<Remote>(io_, peer);
    boost::system::error_code ec;
    const auto address = asio::ip::make_address(peer.address, ec);
    if (!ec) {
      remote->numeric = true;
      remote->endpoint = tcp::endpoint(address, static_cast<unsigned short>(peer.port));
    } else {
      // A name (a StatefulSet's DNS name, say) is looked up now and kept: a slow resolver must never hold
      // up a claim, which has one second per phase.
      resolve(remote);
    }
    remotes_.push_back(std::move(remote));
  }
}

RegistryClient::~RegistryClient() {
  for (const auto& remote : remotes_) {
    remote->resolver.cancel();
    remote->retry.cancel();
  }
}

void RegistryClient::resolve(const std::shared_ptr<Remote>& remote) {
  if (remote->numeric || remote->resolving) return;
  remote->resolving = true;
  remote->last_lookup = std::chrono::steady_clock::now();
  remote->resolver.async_resolve(
      remote->peer.address, std::to_string(remote->peer.port),
      [this, remote](const boost::system::error_code& ec, const tcp::resolver::results_type& results) {
        remote->resolving = false;
        if (ec == asio::error::operation_aborted) return;
        if (!ec && !results.empty()) {
          const tcp::endpoint found = results.begin()->endpoint();
          if (remote->endpoint != found) {
            rfbsim::log::info("registry", "peer %s: %s is %s", remote->peer.id.c_str(), remote->peer.address.c_str(),
                              found.address().to_string().c_str());
          }
          remote->endpoint = found;
          remote->warned = false;
          return;
        }
        if (!remote->warned) {
          rfbsim::log::warn("registry", "peer %s: cannot resolve %s (%s); it counts as down until it does",
                            remote->peer.id.c_str(), remote->peer.address.c_str(), ec.message().c_str());
          remote->warned = true;
        }
        // Never resolved: keep trying in the background. Resolved before: keep the last address.
        if (remote->endpoint) return;
        remote->retry.expires_after(kResolveRetry);
        remote->retry.async_wait([this, remote](const boost::system::error_code& wait_ec) {
          if (!wait_ec) resolve(remote);
        });
      });
}

void RegistryClient::claim(const std::string& uid, Decided done) {
  run_ballot(std::make_shared<Round>(io_, uid, false, [done = std::move(done)](const LearnResult& result) {
    done(result.kind == LearnKind::kDecided ? std::optional<std::string>(result.home) : std::nullopt);
  }));
}

void RegistryClient::learn(const std::string& uid, Learned done) {
  run_ballot(std::make_shared<Round>(io_, uid, true, std::move(done)));
}

void RegistryClient::run_ballot(const std::shared_ptr<Round>& round) {
  ++round->attempt;
  if (counter_ >= kMaxBallotCounter) {
    rfbsim::log::warn("registry", "uid %s: ballot counters are used up", round->uid.c_str());
    round->done(LearnResult{});
    return;
  }
  round->ballot = Ballot{++counter_, self_};
  round->nonce = new_session_token().substr(0, 16);
  round->tally.emplace(self_, ids_);
  run_phase(round, MessageKind::kPrepare);
}

void RegistryClient::run_phase(const std::shared_ptr<Round>& round, MessageKind kind) {
  auto phase = std::make_shared<Phase>(io_, round);
  phase->request.kind = kind;
  phase->request.uid = round->uid;
  phase->request.ballot = round->ballot;
  phase->request.nonce = round->nonce;
  phase->request.unix_time = unix_seconds_now();
  if (kind == MessageKind::kAccept) phase->request.value = round->proposal;

  // One timeout for the whole phase: whoever has not answered by then counts as silent.
  phase->timer.expires_after(phase_timeout_);
  phase->timer.async_wait([this, phase](const boost::system::error_code& ec) {
    if (ec || phase->settled) return;
    for (const std::string& id : ids_) phase->round->tally->silent(id);
    settle(phase);
  });
  // Every acceptor at once, this host's own in-process.
  RegistryMessage own_request = phase->request;
  own_request.acceptor = self_;
  own_.handle(own_request,
              [this, phase](const std::optional<RegistryMessage>& answer) { answered(phase, self_, answer); });
  for (const auto& remote : remotes_) ask(phase, remote);
}

void RegistryClient::ask(const std::shared_ptr<Phase>& phase, const std::shared_ptr<Remote>& remote) {
  const std::string id = remote->peer.id;
  if (!remote->endpoint) {
    // Its name has not resolved (yet): down, for this phase. Posted, so that no answer arrives before every
    // acceptor was asked.
    asio::post(io_, [this, phase, id] { answered(phase, id, std::nullopt); });
    return;
  }
  auto exchange = std::make_shared<Exchange>(io_);
  exchange->request = phase->request;
  exchange->request.acceptor = id;
  exchange->line = format_message(key_, exchange->request);
  phase->exchanges.push_back(exchange);

  auto read_answer = [this, phase, exchange, id](const boost::system::error_code& ec, std::size_t length) {
    if (phase->settled) return;
    if (ec) return answered(phase, id, std::nullopt);
    const auto data = exchange->buffer.data();
    const std::string line(asio::buffers_begin(data), asio::buffers_begin(data) + static_cast<long>(length) - 1);
    const MessageParse parsed = parse_message(line, key_);
    // A wrong answer is no vote: an error line, another secret or peer list, an answer to another question.
    if (!parsed.message || !answers_request(*parsed.message, exchange->request, peers_)) {
      rfbsim::log::limited(rfbsim::log::Level::kWarn, "registry-bad-answer", "registry",
                           "peer %s answered '%.80s'; not counted", id.c_str(), line.c_str());
      return answered(phase, id, std::nullopt);
    }
    answered(phase, id, parsed.message);
  };
  auto connected = [this, phase, exchange, remote, id, read_answer](const boost::system::error_code& ec) {
    if (phase->settled) return;
    if (ec) {
      // Down, or moved: a name is looked up again in the background for the next claim.
      if (std::chrono::steady_clock::now() - remote->last_lookup >= kResolveRefresh) resolve(remote);
      return answered(phase, id, std::nullopt);
    }
    asio::async_write(exchange->socket, asio::buffer(exchange->line),
                      [this, phase, exchange, id, read_answer](const boost::system::error_code& write_ec, std::size_t) {
                        if (phase->settled) return;
                        if (write_ec) return answered(phase, id, std::nullopt);
                        asio::async_read_until(exchange->socket, exchange->buffer, '\n', read_answer);
                      });
  };
  exchange->socket.async_connect(*remote->endpoint, connected);
}

void RegistryClient::answered(const std::shared_ptr<Phase>& phase, const std::string& acceptor,
                              const std::optional<RegistryMessage>& answer) {
  if (phase->settled) return;
  BallotTally& tally = *phase->round->tally;
  if (!answer) {
    tally.silent(acceptor);
  } else if (answer->kind == MessageKind::kPromise) {
    tally.promised(acceptor, answer->other, answer->value);
  } else if (answer->kind == MessageKind::kAccepted) {
    tally.accepted(acceptor);
  } else if (answer->kind == MessageKind::kReject) {
    tally.rejected(acceptor, answer->other);
  } else {
    tally.silent(acceptor);
  }
  settle(phase);
}

void RegistryClient::settle(const std::shared_ptr<Phase>& phase) {
  const std::shared_ptr<Round>& round = phase->round;
  const BallotTally::Progress progress = round->tally->progress();
  if (progress == BallotTally::Progress::kWaiting) return;
  phase->settled = true;
  phase->timer.cancel();
  for (const auto& exchange : phase->exchanges) {
    boost::system::error_code ignored;
    exchange->socket.close(ignored);
  }
  // The next ballot goes above every ballot the answers named.
  counter_ = std::max(counter_, round->tally->highest_counter());
  if (progress == BallotTally::Progress::kFailed) return retry_or_give_up(round);
  if (phase->request.kind == MessageKind::kPrepare) {
    if (round->learn_only) {
      const std::optional<std::string> learned = round->tally->learned_value();
      // No promise of this majority reports a value, so no value was decided (any decided one would show in
      // every majority): there is nothing to learn, and a learn-only round proposes nothing of its own.
      if (!learned) return round->done(LearnResult{LearnKind::kUnknown, ""});
      round->proposal = *learned;
    } else {
      round->proposal = round->tally->value();
    }
    round->tally->begin_accept();
    run_phase(round, MessageKind::kAccept);
    return;
  }
  // A majority accepted this value at this ballot: it is decided, for good.
  round->done(LearnResult{LearnKind::kDecided, phase->request.value});
}

void RegistryClient::retry_or_give_up(const std::shared_ptr<Round>& round) {
  if (round->attempt >= kAttempts) {
    rfbsim::log::warn("registry", "uid %s: no home %s after %d ballots; the participant retries", round->uid.c_str(),
                      round->learn_only ? "learned" : "decided", round->attempt);
    round->done(LearnResult{});
    return;
  }
  std::uniform_int_distribution<int> pause_ms(kRetryPauseMinMs, kRetryPauseMaxMs);
  round->pause.expires_after(std::chrono::milliseconds(pause_ms(random_)));
  round->pause.async_wait([this, round](const boost::system::error_code& ec) {
    if (!ec) run_ballot(round);
  });
}

}  // namespace rfbsim::manager
