// SPDX-License-Identifier: GPL-2.0-or-later
// The uid registry's rules: an acceptor's two steps, a proposer's tally, and the signed line format.
#include "cluster/uid_registry.hpp"

#include <openssl/crypto.h>

#include <algorithm>
#include <charconv>

#include "admission/link_signature.hpp"
#include "admission/start_request.hpp"

namespace rfbsim::manager {

namespace {

constexpr std::size_t kNonceLength = 16;

// Splits on single spaces; an empty field (two spaces, a leading or trailing one) makes the line malformed.
std::vector<std::string_view> fields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t space = line.find(' ', start);
    out.push_back(line.substr(start, space == std::string_view::npos ? std::string_view::npos : space - start));
    if (space == std::string_view::npos) break;
    start = space + 1;
  }
  return out;
}

bool same_hmac(std::string_view given, const std::string& expected) {
  return given.size() == expected.size() && CRYPTO_memcmp(given.data(), expected.data(), expected.size()) == 0;
}

bool is_nonce(std::string_view text) {
  return text.size() == kNonceLength && std::all_of(text.begin(), text.end(), [](char ch) {
           return (ch >= '0' && ch <= '9') || (ch >= 'a' && ch <= 'f');
         });
}

// A decimal number, all of `text` (no sign, no spaces).
template <typename Number>
bool parse_number(std::string_view text, Number& out) {
  if (text.empty() || text.front() == '-' || text.front() == '+') return false;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && ptr == text.data() + text.size();
}

const char* kind_word(MessageKind kind) {
  switch (kind) {
    case MessageKind::kPrepare:
      return "prepare";
    case MessageKind::kAccept:
      return "accept";
    case MessageKind::kPromise:
      return "promise";
    case MessageKind::kAccepted:
      return "accepted";
    case MessageKind::kReject:
      return "reject";
  }
  return "?";
}

// Each kind's field count, its leading word and the five common fields included, the hmac not.
std::size_t field_count(MessageKind kind) {
  switch (kind) {
    case MessageKind::kPrepare:
      return 7;
    case MessageKind::kAccept:
      return 8;
    case MessageKind::kPromise:
      return 9;
    case MessageKind::kAccepted:
      return 6;
    case MessageKind::kReject:
      return 8;
  }
  return 0;
}

bool is_peer(const std::vector<ClusterPeer>& peers, const std::string& id) {
  return std::any_of(peers.begin(), peers.end(), [&](const ClusterPeer& peer) { return peer.id == id; });
}

}  // namespace

bool is_host_id(std::string_view text) {
  if (text.empty() || text.size() > 32) return false;
  return std::all_of(text.begin(), text.end(),
                     [](char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '-'; });
}

// --- The acceptor -------------------------------------------------------------------------------------------

bool acceptor_prepare(AcceptorState& state, const Ballot& ballot) {
  if (ballot.empty() || !(ballot > state.promised)) return false;
  state.promised = ballot;
  return true;
}

bool acceptor_accept(AcceptorState& state, const Ballot& ballot, const std::string& value) {
  if (ballot.empty() || ballot < state.promised) return false;
  state.promised = ballot;
  state.accepted = ballot;
  state.value = value;
  return true;
}

RegistryMessage acceptor_answer(AcceptorState& state, const RegistryMessage& request) {
  RegistryMessage answer;
  answer.uid = request.uid;
  answer.ballot = request.ballot;
  answer.acceptor = request.acceptor;
  answer.nonce = request.nonce;
  const bool yes = request.kind == MessageKind::kPrepare ? acceptor_prepare(state, request.ballot)
                                                         : acceptor_accept(state, request.ballot, request.value);
  if (!yes) {
    answer.kind = MessageKind::kReject;
    answer.other = state.promised;
  } else if (request.kind == MessageKind::kPrepare) {
    answer.kind = MessageKind::kPromise;
    answer.other = state.accepted;
    answer.value = state.value;
  } else {
    answer.kind = MessageKind::kAccepted;
  }
  return answer;
}

// --- The proposer's tally -----------------------------------------------------------------------------------

BallotTally::BallotTally(std::string self, std::vector<std::string> acceptors)
    : self_(std::move(self)), acceptors_(std::move(acceptors)) {}

bool BallotTally::counts(const std::string& acceptor) const {
  // One vote per acceptor and phase: a second answer of the same acceptor is not a second vote.
  return std::find(acceptors_.begin(), acceptors_.end(), acceptor) != acceptors_.end() && yes_.count(acceptor) == 0 &&
         no_.count(acceptor) == 0;
}

void BallotTally::promised(const std::string& acceptor, const Ballot& accepted, const std::string& value) {
  if (!counts(acceptor)) return;
  yes_.insert(acceptor);
  highest_counter_ = std::max(highest_counter_, accepted.counter);
  if (!accepted.empty() && accepted > best_accepted_) {
    best_accepted_ = accepted;
    best_value_ = value;
  }
}

void BallotTally::accepted(const std::string& acceptor) {
  if (counts(acceptor)) yes_.insert(acceptor);
}

void BallotTally::rejected(const std::string& acceptor, const Ballot& promised) {
  if (!counts(acceptor)) return;
  no_.insert(acceptor);
  highest_counter_ = std::max(highest_counter_, promised.counter);
}

void BallotTally::silent(const std::string& acceptor) {
  if (counts(acceptor)) no_.insert(acceptor);
}

BallotTally::Progress BallotTally::progress() const {
  const std::size_t n = acceptors_.size();
  if (2 * yes_.size() > n) return Progress::kMajority;
  // Even if every acceptor still to answer said yes, not more than half would have.
  if (2 * (n - no_.size()) <= n) return Progress::kFailed;
  return Progress::kWaiting;
}

void BallotTally::begin_accept() {
  yes_.clear();
  no_.clear();
}

const std::string& BallotTally::value() const { return best_accepted_.empty() ? self_ : best_value_; }

std::optional<std::string> BallotTally::learned_value() const {
  if (best_accepted_.empty()) return std::nullopt;
  return best_value_;
}

std::optional<std::string> learned_redirect(const LearnResult& result, const std::string& self) {
  if (result.kind != LearnKind::kDecided || result.home.empty() || result.home == self) return std::nullopt;
  return result.home;
}

// --- Lines --------------------------------------------------------------------------------------------------

std::string registry_key(std::string_view secret, const std::vector<ClusterPeer>& peers) {
  std::vector<std::string> lines;
  lines.reserve(peers.size());
  for (const ClusterPeer& peer : peers) lines.push_back(peer.id + "=" + peer.address + ":" + std::to_string(peer.port));
  std::sort(lines.begin(), lines.end());
  std::string text = "rfbsim-registry-v2\n";
  for (const std::string& line : lines) text += line + "\n";
  return hmac_sha256_hex(secret, text);
}

std::string format_message(std::string_view key, const RegistryMessage& message) {
  std::string text = std::string(kind_word(message.kind)) + " " + message.uid + " " +
                     std::to_string(message.ballot.counter) + " " + message.ballot.proposer + " " + message.acceptor +
                     " " + message.nonce;
  switch (message.kind) {
    case MessageKind::kPrepare:
      text += " " + std::to_string(message.unix_time);
      break;
    case MessageKind::kAccept:
      text += " " + std::to_string(message.unix_time) + " " + message.value;
      break;
    case MessageKind::kPromise:
      text += message.other.empty() ? std::string(" 0 - -")
                                    : " " + std::to_string(message.other.counter) + " " + message.other.proposer +
                                          " " + message.value;
      break;
    case MessageKind::kAccepted:
      break;
    case MessageKind::kReject:
      // An acceptor that refuses has promised something: at least the ballot it refuses.
      text += " " + std::to_string(message.other.counter) + " " + message.other.proposer;
      break;
  }
  return text + " " + hmac_sha256_hex(key, text) + "\n";
}

MessageParse parse_message(std::string_view line, std::string_view key) {
  MessageParse out;
  auto refuse = [&out](const char* why) {
    out.error = why;
    return out;
  };
  if (line.size() + 1 > kMaxRegistryLine) return refuse("line too long");
  const auto parts = fields(line);
  RegistryMessage m;
  static constexpr MessageKind kKinds[] = {MessageKind::kPrepare, MessageKind::kAccept, MessageKind::kPromise,
                                           MessageKind::kAccepted, MessageKind::kReject};
  const auto kind = std::find_if(std::begin(kKinds), std::end(kKinds),
                                 [&](MessageKind k) { return parts[0] == kind_word(k); });
  if (kind == std::end(kKinds)) return refuse("expected prepare, accept, promise, accepted or reject");
  m.kind = *kind;
  if (parts.size() != field_count(m.kind) + 1) return refuse("wrong number of fields");
  if (!is_identifier(parts[1])) return refuse("bad uid");
  m.uid = std::string(parts[1]);
  if (!parse_number(parts[2], m.ballot.counter) || m.ballot.counter == 0 || m.ballot.counter > kMaxBallotCounter) {
    return refuse("bad ballot");
  }
  if (!is_host_id(parts[3]) || !is_host_id(parts[4])) return refuse("bad host");
  m.ballot.proposer = std::string(parts[3]);
  m.acceptor = std::string(parts[4]);
  if (!is_nonce(parts[5])) return refuse("bad nonce");
  m.nonce = std::string(parts[5]);
  switch (m.kind) {
    case MessageKind::kPrepare:
    case MessageKind::kAccept:
      if (!parse_number(parts[6], m.unix_time)) return refuse("bad time");
      if (m.kind == MessageKind::kAccept) {
        if (!is_host_id(parts[7])) return refuse("bad host");
        m.value = std::string(parts[7]);
      }
      break;
    case MessageKind::kPromise:
      if (parts[6] == "0") {
        if (parts[7] != "-" || parts[8] != "-") return refuse("bad accepted ballot");
      } else {
        if (!parse_number(parts[6], m.other.counter) || m.other.counter > kMaxBallotCounter ||
            !is_host_id(parts[7]) || !is_host_id(parts[8])) {
          return refuse("bad accepted ballot");
        }
        m.other.proposer = std::string(parts[7]);
        m.value = std::string(parts[8]);
      }
      break;
    case MessageKind::kAccepted:
      break;
    case MessageKind::kReject:
      if (!parse_number(parts[6], m.other.counter) || m.other.counter == 0 || m.other.counter > kMaxBallotCounter ||
          !is_host_id(parts[7])) {
        return refuse("bad promised ballot");
      }
      m.other.proposer = std::string(parts[7]);
      break;
  }
  // The hmac covers every byte before it: no field can be changed, added or moved.
  const std::string_view signed_text = line.substr(0, line.size() - parts.back().size() - 1);
  if (!same_hmac(parts.back(), hmac_sha256_hex(key, signed_text))) return refuse("bad hmac");
  out.message = std::move(m);
  return out;
}

std::string request_problem(const RegistryMessage& request, const std::string& self,
                            const std::vector<ClusterPeer>& peers, long long now_unix) {
  if (request.kind != MessageKind::kPrepare && request.kind != MessageKind::kAccept) return "not a request";
  // Addressed to another acceptor: a peer entry that points at this host's port, or a request passed on.
  if (request.acceptor != self) return "not acceptor " + request.acceptor;
  if (!is_peer(peers, request.ballot.proposer)) return "proposer not a peer";
  if (request.kind == MessageKind::kAccept && !is_peer(peers, request.value)) return "value not a peer";
  if (request.unix_time > now_unix + kClaimMaxSkew.count() || request.unix_time < now_unix - kClaimMaxSkew.count()) {
    return "stale time";
  }
  return "";
}

bool answers_request(const RegistryMessage& answer, const RegistryMessage& request,
                     const std::vector<ClusterPeer>& peers) {
  const bool fits = request.kind == MessageKind::kPrepare
                        ? answer.kind == MessageKind::kPromise || answer.kind == MessageKind::kReject
                        : answer.kind == MessageKind::kAccepted || answer.kind == MessageKind::kReject;
  if (!fits || answer.uid != request.uid || answer.ballot != request.ballot || answer.acceptor != request.acceptor ||
      answer.nonce != request.nonce) {
    return false;
  }
  if (answer.kind == MessageKind::kPromise && !answer.other.empty() &&
      (!is_peer(peers, answer.value) || !is_peer(peers, answer.other.proposer))) {
    return false;
  }
  // A refusal names the ballot it promised, which must be at least the one refused.
  if (answer.kind == MessageKind::kReject &&
      (!is_peer(peers, answer.other.proposer) || answer.other < request.ballot)) {
    return false;
  }
  return true;
}

std::string error_line(std::string_view reason) {
  std::string out = "error ";
  for (const char ch : reason.substr(0, 128)) out.push_back(ch >= 0x20 && ch < 0x7f ? ch : '?');
  return out + "\n";
}

}  // namespace rfbsim::manager
