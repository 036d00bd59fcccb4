// SPDX-License-Identifier: GPL-2.0-or-later
// The uid registry's rules, apart from sockets and SQLite: single-decree Paxos per uid (an acceptor's two
// rules, a proposer's count of one ballot's answers) and the signed one-line messages the hosts exchange.
// Pure, unit-tested.
//
// Why Paxos: every host is an acceptor of every uid's home. A proposer first asks a majority to promise to
// ignore lower ballots and to tell what they accepted (prepare/promise), then asks them to accept the value
// with the highest ballot among those answers, or itself when there is none (accept/accepted). Once a
// majority accepted one value at one ballot, every higher ballot's promises include one of those acceptors,
// so every later proposal is that value: at most one home is ever decided, whatever hosts are down,
// restarted or proposing at once, and a higher ballot can always finish a split that an earlier round left
// (a first-answer-wins record could lock a uid out for good). Safety needs only that two majorities share an
// acceptor; the message key is derived from the peer list, so hosts started on different lists (whose
// majorities need not intersect) cannot count each other's answers.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "config/config.hpp"

namespace rfbsim::manager {

/// The longest registry line, its newline included: a promise with a 64-character uid and 32-character host
/// ids is about 330 bytes.
inline constexpr std::size_t kMaxRegistryLine = 512;
/// How far a request's time may be from the acceptor's clock, either way: a replayed request is stale after this.
inline constexpr std::chrono::seconds kClaimMaxSkew{120};

/// The largest ballot counter: SQLite stores it as a signed 64-bit integer.
inline constexpr std::uint64_t kMaxBallotCounter = 0x7fffffffffffffffULL;

/// Whether `text` is a host id as cluster_peers and path prefixes need it: 1..32 of [a-z0-9-].
bool is_host_id(std::string_view text);

/// A Paxos ballot: compared by counter, then by proposer id. Counter 0 is "no ballot" (nothing promised or
/// accepted); a proposer's ballots start at 1.
struct Ballot {
  std::uint64_t counter = 0;
  std::string proposer;  ///< the proposing host's id; "" with counter 0

  [[nodiscard]] bool empty() const { return counter == 0; }
  friend bool operator<(const Ballot& a, const Ballot& b) {
    return a.counter != b.counter ? a.counter < b.counter : a.proposer < b.proposer;
  }
  friend bool operator==(const Ballot& a, const Ballot& b) {
    return a.counter == b.counter && a.proposer == b.proposer;
  }
  friend bool operator!=(const Ballot& a, const Ballot& b) { return !(a == b); }
  friend bool operator>(const Ballot& a, const Ballot& b) { return b < a; }
  friend bool operator>=(const Ballot& a, const Ballot& b) { return !(a < b); }
};

/// What one acceptor holds for one uid (kept in sessions.db, committed before it answers).
struct AcceptorState {
  Ballot promised;    ///< the highest ballot it promised; lower ones are rejected
  Ballot accepted;    ///< the ballot of the value it accepted last (empty: none)
  std::string value;  ///< that value, a host id ("" when none)

  friend bool operator==(const AcceptorState& a, const AcceptorState& b) {
    return a.promised == b.promised && a.accepted == b.accepted && a.value == b.value;
  }
  friend bool operator!=(const AcceptorState& a, const AcceptorState& b) { return !(a == b); }
};

/// Phase 1 at an acceptor: promises `ballot` (and records it) when it is above every ballot promised so far;
/// a repeated ballot is refused too, so that a proposer restarted with the same counter cannot gather two
/// majorities for one ballot. Returns whether it promised.
bool acceptor_prepare(AcceptorState& state, const Ballot& ballot);

/// Phase 2 at an acceptor: accepts `value` at `ballot` unless it promised a higher ballot. Returns whether
/// it accepted.
bool acceptor_accept(AcceptorState& state, const Ballot& ballot, const std::string& value);

/// A proposer's count of one ballot's answers, phase 1 then phase 2. Each acceptor counts once per phase
/// (an answer repeated, or from a host not among the acceptors, changes nothing).
class BallotTally {
 public:
  /// Where the current phase stands.
  enum class Progress {
    kWaiting,   ///< neither a majority nor its impossibility yet
    kMajority,  ///< more than half of the acceptors said yes
    kFailed,    ///< too many said no or did not answer for a majority
  };

  /// A ballot of `self` over `acceptors` (every configured peer, this host included).
  BallotTally(std::string self, std::vector<std::string> acceptors);

  /// Phase 1: `acceptor` promised, and had accepted `value` at `accepted` (empty: nothing).
  void promised(const std::string& acceptor, const Ballot& accepted, const std::string& value);
  /// Phase 2: `acceptor` accepted.
  void accepted(const std::string& acceptor);
  /// Either phase: `acceptor` refused, having promised `promised`.
  void rejected(const std::string& acceptor, const Ballot& promised);
  /// Either phase: no valid answer from `acceptor` (down, slow, a line that did not verify).
  void silent(const std::string& acceptor);
  /// The current phase's standing.
  [[nodiscard]] Progress progress() const;
  /// Starts phase 2: the answers are counted afresh.
  void begin_accept();
  /// What phase 2 proposes: the value of the highest accepted ballot among the promises, else this host.
  [[nodiscard]] const std::string& value() const;
  /// What a learn-only round's phase 2 proposes: the value of the highest accepted ballot among the promises,
  /// or nothing when no promise reported one (that round then ends "unknown" without a phase 2).
  [[nodiscard]] std::optional<std::string> learned_value() const;
  /// The highest ballot counter any answer named (accepted or promised ballots): the next ballot goes above.
  [[nodiscard]] std::uint64_t highest_counter() const { return highest_counter_; }
  /// How many acceptors answered yes in the current phase.
  [[nodiscard]] std::size_t yes_count() const { return yes_.size(); }

 private:
  bool counts(const std::string& acceptor) const;
  std::string self_;
  std::vector<std::string> acceptors_;
  std::set<std::string> yes_;
  std::set<std::string> no_;
  Ballot best_accepted_;
  std::string best_value_;
  std::uint64_t highest_counter_ = 0;
};

/// How a learn-only round ended. Such a round never proposes its own host: it only finishes what a majority
/// may already have decided, so a full or draining host can send a uid's participant to the uid's home
/// without ever becoming that home.
enum class LearnKind {
  kDecided,    ///< phase 2 of this round got a majority to accept `home`: the uid's home, for good
  kUnknown,    ///< a majority promised and none had accepted a value: no home yet, and none was proposed
  kUndecided,  ///< no ballot got a majority (too many peers down, or outbid each time): nothing learned
};

/// A learn-only round's result: its kind and, when decided, the uid's home.
struct LearnResult {
  LearnKind kind = LearnKind::kUndecided;
  std::string home;  ///< the decided home ("" unless kDecided)
};

/// Where a host that may not start `uid` (full, draining) sends its participant after a learn-only round:
/// the decided home when that is another host, else nothing (the busy page; the balancer or the participant
/// tries elsewhere, which is safe because nothing was claimed). A home of `self` is nothing too: this host
/// owns the uid but has no room for it now.
std::optional<std::string> learned_redirect(const LearnResult& result, const std::string& self);

/// The message key: hex HMAC-SHA256(secret, "rfbsim-registry-v2\n" + the peers as "id=address:port\n"
/// lines, sorted). Hosts on different peer lists get different keys and cannot count each other's answers.
std::string registry_key(std::string_view secret, const std::vector<ClusterPeer>& peers);

/// The kinds of registry line: two requests (a proposer to an acceptor) and three answers.
enum class MessageKind { kPrepare, kAccept, kPromise, kAccepted, kReject };

/// One registry message. Every kind names the uid, the proposer's ballot (its proposer included), the
/// acceptor asked or answering, and the proposer's nonce for this ballot, so that an answer cannot be passed
/// off for another uid, ballot, acceptor or round. Lines (each ends with " <hmac>\n", the hex HMAC-SHA256
/// under registry_key of everything before it):
///   prepare  <uid> <counter> <proposer> <acceptor> <nonce> <unix_time>
///   accept   <uid> <counter> <proposer> <acceptor> <nonce> <unix_time> <value>
///   promise  <uid> <counter> <proposer> <acceptor> <nonce> <accepted_counter> <accepted_proposer> <value>
///            (nothing accepted: "0 - -")
///   accepted <uid> <counter> <proposer> <acceptor> <nonce>
///   reject   <uid> <counter> <proposer> <acceptor> <nonce> <promised_counter> <promised_proposer>
struct RegistryMessage {
  MessageKind kind = MessageKind::kPrepare;
  std::string uid;       ///< a /start uid: letters, digits, - and _, 1..64
  Ballot ballot;         ///< the proposer's ballot (counter >= 1)
  std::string acceptor;  ///< the acceptor asked (requests) or answering (answers)
  std::string nonce;     ///< 16 hex digits the proposer drew for this ballot
  long long unix_time = 0;  ///< requests: when the proposer sent it, Unix seconds
  std::string value;     ///< accept: the proposed home; promise: the accepted value ("" when none)
  Ballot other;          ///< promise: the accepted ballot (empty: none); reject: the acceptor's promised ballot
};

/// The signed line for `message`, newline included.
std::string format_message(std::string_view key, const RegistryMessage& message);

/// A parsed line, or why it was refused (words for an `error` answer).
struct MessageParse {
  std::optional<RegistryMessage> message;
  std::string error;
};

/// Reads one line (without its newline): refuses one over kMaxRegistryLine, an unknown kind, a wrong field
/// count, a bad uid, host id, counter or nonce, and a wrong hmac (compared in constant time). Checks no
/// clock and no peer list: see request_problem and answers_request.
MessageParse parse_message(std::string_view line, std::string_view key);

/// Why an acceptor `self` refuses `request` ("" when it takes it): not a request, addressed to another
/// acceptor, a proposer or value not among `peers`, or a time further than kClaimMaxSkew from `now_unix`.
std::string request_problem(const RegistryMessage& request, const std::string& self,
                            const std::vector<ClusterPeer>& peers, long long now_unix);

/// Whether `answer` is an answer to `request` that the proposer may count: an answer kind that fits the
/// request's phase, the same uid, ballot, acceptor and nonce, and every host it names among `peers`.
bool answers_request(const RegistryMessage& answer, const RegistryMessage& request,
                     const std::vector<ClusterPeer>& peers);

/// The acceptor's answer to `request` (a prepare or accept already checked with request_problem) given its
/// state for the uid, which it updates: the state must be committed before the answer leaves.
RegistryMessage acceptor_answer(AcceptorState& state, const RegistryMessage& request);

/// "error <reason>\n", the reason reduced to printable ASCII on one line.
std::string error_line(std::string_view reason);

}  // namespace rfbsim::manager
