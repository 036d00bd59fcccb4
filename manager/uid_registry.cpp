// SPDX-License-Identifier: GPL-2.0-or-later
// The uid registry's rules: rendezvous order, the tally, and the signed line format.
#include "uid_registry.hpp"

#include <openssl/crypto.h>
#include <openssl/sha.h>

#include <algorithm>
#include <array>
#include <charconv>

#include "link_signature.hpp"
#include "start_request.hpp"

namespace rfbsim::manager {

namespace {

using Digest = std::array<unsigned char, SHA256_DIGEST_LENGTH>;

Digest sha256(std::string_view text) {
  Digest digest{};
  SHA256(reinterpret_cast<const unsigned char*>(text.data()), text.size(), digest.data());
  return digest;
}

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

}  // namespace

bool is_host_id(std::string_view text) {
  if (text.empty() || text.size() > 32) return false;
  return std::all_of(text.begin(), text.end(),
                     [](char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '-'; });
}

std::vector<ClusterPeer> rendezvous_order(std::string_view uid, std::vector<ClusterPeer> peers) {
  std::vector<std::pair<Digest, ClusterPeer>> keyed;
  keyed.reserve(peers.size());
  for (ClusterPeer& peer : peers) {
    keyed.emplace_back(sha256(std::string(uid) + "|" + peer.id), std::move(peer));
  }
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
    if (a.first != b.first) return a.first > b.first;
    return a.second.id < b.second.id;
  });
  std::vector<ClusterPeer> out;
  out.reserve(keyed.size());
  for (auto& [digest, peer] : keyed) out.push_back(std::move(peer));
  return out;
}

ClaimTally::ClaimTally(std::string self, int peer_count) : proposal_(std::move(self)), peer_count_(peer_count) {}

void ClaimTally::answered(const std::string& owner) {
  ++votes_[owner];
  proposal_ = owner;
}

std::optional<std::string> ClaimTally::decided() const {
  for (const auto& [owner, count] : votes_) {
    if (2 * count > peer_count_) return owner;
  }
  return std::nullopt;
}

std::string claim_line(std::string_view secret, std::string_view uid, std::string_view host, long long unix_time) {
  const std::string text = "claim " + std::string(uid) + " " + std::string(host) + " " + std::to_string(unix_time);
  return text + " " + hmac_sha256_hex(secret, text) + "\n";
}

ClaimParse parse_claim_line(std::string_view line, std::string_view secret, long long now_unix) {
  ClaimParse out;
  if (line.size() + 1 > kMaxRegistryLine) {
    out.error = "line too long";
    return out;
  }
  const auto parts = fields(line);
  if (parts.size() != 5 || parts[0] != "claim") {
    out.error = "expected: claim <uid> <host> <unix_time> <hmac>";
    return out;
  }
  if (!is_identifier(parts[1])) {
    out.error = "bad uid";
    return out;
  }
  if (!is_host_id(parts[2])) {
    out.error = "bad host";
    return out;
  }
  long long time = 0;
  const auto [ptr, ec] = std::from_chars(parts[3].data(), parts[3].data() + parts[3].size(), time);
  if (parts[3].empty() || ec != std::errc() || ptr != parts[3].data() + parts[3].size() || time < 0) {
    out.error = "bad time";
    return out;
  }
  // The signature before the clock: an unsigned line learns nothing, not even whether its time would pass.
  const std::string signed_text = std::string(line.substr(0, line.size() - parts[4].size() - 1));
  if (!same_hmac(parts[4], hmac_sha256_hex(secret, signed_text))) {
    out.error = "bad hmac";
    return out;
  }
  if (time > now_unix + kClaimMaxSkew.count() || time < now_unix - kClaimMaxSkew.count()) {
    out.error = "stale time";
    return out;
  }
  out.claim = RegistryClaim{std::string(parts[1]), std::string(parts[2]), time};
  return out;
}

std::string owner_line(std::string_view secret, std::string_view uid, std::string_view host) {
  return "owner " + std::string(host) + " " +
         hmac_sha256_hex(secret, "owner " + std::string(uid) + " " + std::string(host)) + "\n";
}

std::optional<std::string> parse_owner_line(std::string_view line, std::string_view secret, std::string_view uid) {
  if (line.size() + 1 > kMaxRegistryLine) return std::nullopt;
  const auto parts = fields(line);
  if (parts.size() != 3 || parts[0] != "owner" || !is_host_id(parts[1])) return std::nullopt;
  const std::string expected =
      hmac_sha256_hex(secret, "owner " + std::string(uid) + " " + std::string(parts[1]));
  if (!same_hmac(parts[2], expected)) return std::nullopt;
  return std::string(parts[1]);
}

std::string error_line(std::string_view reason) {
  std::string out = "error ";
  for (const char ch : reason.substr(0, 128)) out.push_back(ch >= 0x20 && ch < 0x7f ? ch : '?');
  return out + "\n";
}

}  // namespace rfbsim::manager
