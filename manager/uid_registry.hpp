// SPDX-License-Identifier: GPL-2.0-or-later
// The uid registry's rules, apart from sockets and SQLite: which peers a claim asks in which order, how the
// answers decide a uid's home, and the signed one-line messages the peers exchange. Pure, unit-tested.
//
// Why a majority: every acceptor records one home per uid, forever (the first it is asked for). A home that a
// majority of the N configured peers answered is therefore on a majority, and two majorities share a peer,
// which recorded one value only: at most one host can ever be decided as a uid's home, whatever hosts are
// down, restarted or asked at the same time.
#pragma once

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config.hpp"

namespace rfbsim::manager {

/// The longest registry line, its newline included: a claim with a 64-character uid is about 180 bytes.
inline constexpr std::size_t kMaxRegistryLine = 256;
/// How far a claim's time may be from the acceptor's clock, either way: a replayed claim is stale after this.
inline constexpr std::chrono::seconds kClaimMaxSkew{120};

/// Whether `text` is a host id as cluster_peers and path prefixes need it: 1..32 of [a-z0-9-].
bool is_host_id(std::string_view text);

/// `peers` in `uid`'s rendezvous order: by SHA-256(uid + "|" + id), highest first (ties, which need equal
/// hashes, by id). The same uid gives every host the same order, so concurrent claims meet at the same
/// first acceptor; different uids spread their first acceptor over the peers.
std::vector<ClusterPeer> rendezvous_order(std::string_view uid, std::vector<ClusterPeer> peers);

/// One claim round's bookkeeping: what to propose next, and whether the answers so far decide the home.
class ClaimTally {
 public:
  /// A round of `self` (this host's id) over `peer_count` configured peers (this host included).
  ClaimTally(std::string self, int peer_count);

  /// The home to propose to the next acceptor: this host, until an acceptor names another.
  [[nodiscard]] const std::string& proposal() const { return proposal_; }
  /// An acceptor answered that `owner` is the uid's home: counted, and adopted as the proposal from now on
  /// (an acceptor's record never changes, so proposing anything else to the rest could only split the vote).
  void answered(const std::string& owner);
  /// The home that more than half of the configured peers answered, if any.
  [[nodiscard]] std::optional<std::string> decided() const;

 private:
  std::string proposal_;
  int peer_count_;
  std::map<std::string, int> votes_;
};

/// A claim as an acceptor reads it.
struct RegistryClaim {
  std::string uid;   ///< a /start uid: letters, digits, - and _, 1..64
  std::string host;  ///< the proposed home, a host id
  long long unix_time = 0;  ///< when the claimer sent it, Unix seconds
};

/// A parsed claim line, or why it was refused (words for an `error` answer).
struct ClaimParse {
  std::optional<RegistryClaim> claim;
  std::string error;
};

/// "claim <uid> <host> <unix_time> <hmac>\n", hmac = hex HMAC-SHA256(secret, "claim <uid> <host> <unix_time>").
std::string claim_line(std::string_view secret, std::string_view uid, std::string_view host, long long unix_time);

/// Reads one claim line (`line` without its newline). Refuses a line over kMaxRegistryLine, a bad uid or
/// host, a time further than kClaimMaxSkew from `now_unix`, and a wrong hmac (compared in constant time).
ClaimParse parse_claim_line(std::string_view line, std::string_view secret, long long now_unix);

/// "owner <host> <hmac>\n", hmac = hex HMAC-SHA256(secret, "owner <uid> <host>"): the uid binds the answer to
/// the question, so that an answer for another uid cannot be passed off for this one.
std::string owner_line(std::string_view secret, std::string_view uid, std::string_view host);

/// The home an acceptor's answer names (`line` without its newline), if it is a well-formed owner line for
/// `uid` signed with `secret`; nothing for anything else (error lines included).
std::optional<std::string> parse_owner_line(std::string_view line, std::string_view secret, std::string_view uid);

/// "error <reason>\n", the reason reduced to printable ASCII on one line.
std::string error_line(std::string_view reason);

}  // namespace rfbsim::manager
