// SPDX-License-Identifier: GPL-2.0-or-later
// The uid registry's pure rules (order, tally, signed lines), its record in the index, and its settings.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "config.hpp"
#include "link_signature.hpp"
#include "scratch_dir.hpp"
#include "session_index.hpp"
#include "uid_registry.hpp"

using rfbsim::manager::ClaimTally;
using rfbsim::manager::ClusterPeer;
using rfbsim::manager::hmac_sha256_hex;
using rfbsim::manager::is_host_id;
using rfbsim::manager::kMaxRegistryLine;
using rfbsim::manager::owner_line;
using rfbsim::manager::parse_claim_line;
using rfbsim::manager::parse_manager_args;
using rfbsim::manager::parse_owner_line;
using rfbsim::manager::rendezvous_order;
using rfbsim::manager::SessionIndex;

namespace {

const std::string kSecret = "0123456789abcdef-cluster";
constexpr long long kNow = 1795515330;  // 2026-11-24T10:15:30Z

std::vector<ClusterPeer> three_peers() {
  return {{"h1", "127.0.0.1", 7001}, {"h2", "127.0.0.1", 7002}, {"h3", "127.0.0.1", 7003}};
}

std::vector<std::string> ids(const std::vector<ClusterPeer>& peers) {
  std::vector<std::string> out;
  for (const ClusterPeer& peer : peers) out.push_back(peer.id);
  return out;
}

// The claim line without its newline, as the acceptor reads it.
std::string claim(const std::string& uid, const std::string& host, long long time,
                  const std::string& secret = kSecret) {
  std::string line = rfbsim::manager::claim_line(secret, uid, host, time);
  line.pop_back();
  return line;
}

std::string chomp(std::string line) {
  if (!line.empty() && line.back() == '\n') line.pop_back();
  return line;
}

}  // namespace

TEST_CASE("host ids are 1-32 of a-z, 0-9 and -", "[uid_registry]") {
  CHECK(is_host_id("h1"));
  CHECK(is_host_id("gpu-host-07"));
  CHECK(is_host_id(std::string(32, 'a')));
  CHECK_FALSE(is_host_id(""));
  CHECK_FALSE(is_host_id(std::string(33, 'a')));
  CHECK_FALSE(is_host_id("H1"));
  CHECK_FALSE(is_host_id("h_1"));
  CHECK_FALSE(is_host_id("h 1"));
}

TEST_CASE("rendezvous order: SHA-256(uid|id) descending, whatever order the peers are listed in", "[uid_registry]") {
  // Expected orders computed independently (Python hashlib).
  CHECK(ids(rendezvous_order("p01", three_peers())) == std::vector<std::string>{"h3", "h1", "h2"});
  CHECK(ids(rendezvous_order("p02", three_peers())) == std::vector<std::string>{"h2", "h3", "h1"});
  auto reversed = three_peers();
  std::reverse(reversed.begin(), reversed.end());
  CHECK(ids(rendezvous_order("p02", reversed)) == std::vector<std::string>{"h2", "h3", "h1"});
  const auto ordered = rendezvous_order("p01", three_peers());
  CHECK(ordered[0].port == 7003);  // the whole entry moves, not just its id
  CHECK(rendezvous_order("p01", {}).empty());
}

TEST_CASE("a tally decides on more than half of the configured peers", "[uid_registry]") {
  SECTION("three peers: two agreeing answers decide") {
    ClaimTally tally("h2", 3);
    CHECK(tally.proposal() == "h2");
    tally.answered("h2");
    CHECK_FALSE(tally.decided());
    tally.answered("h2");
    CHECK(tally.decided() == std::optional<std::string>("h2"));
  }
  SECTION("another owner's answer is adopted as the proposal and counted") {
    ClaimTally tally("h2", 3);
    tally.answered("h1");
    CHECK(tally.proposal() == "h1");
    CHECK_FALSE(tally.decided());
    tally.answered("h1");
    CHECK(tally.decided() == std::optional<std::string>("h1"));
  }
  SECTION("split answers decide nothing") {
    ClaimTally tally("h2", 3);
    tally.answered("h2");
    tally.answered("h1");
    CHECK(tally.proposal() == "h1");
    CHECK_FALSE(tally.decided());
  }
  SECTION("too many peers down: one answer of three is undecided") {
    ClaimTally tally("h1", 3);
    tally.answered("h1");
    CHECK_FALSE(tally.decided());
  }
  SECTION("four peers need three: two is half, not a majority") {
    ClaimTally tally("h1", 4);
    tally.answered("h1");
    tally.answered("h1");
    CHECK_FALSE(tally.decided());
    tally.answered("h1");
    CHECK(tally.decided() == std::optional<std::string>("h1"));
  }
  SECTION("a single host decides alone") {
    ClaimTally tally("h1", 1);
    tally.answered("h1");
    CHECK(tally.decided() == std::optional<std::string>("h1"));
  }
}

TEST_CASE("claim lines: signed, fresh, well-formed, or refused with a reason", "[uid_registry]") {
  const std::string line = claim("p-01_x", "h2", kNow);
  CHECK(line == "claim p-01_x h2 1795515330 " + hmac_sha256_hex(kSecret, "claim p-01_x h2 1795515330"));

  const auto good = parse_claim_line(line, kSecret, kNow);
  REQUIRE(good.claim);
  CHECK(good.claim->uid == "p-01_x");
  CHECK(good.claim->host == "h2");
  CHECK(good.claim->unix_time == kNow);
  CHECK(parse_claim_line(claim("p1", "h2", kNow - 120), kSecret, kNow).claim);
  CHECK(parse_claim_line(claim("p1", "h2", kNow + 120), kSecret, kNow).claim);

  SECTION("tampered or foreign signatures") {
    std::string tampered = line;
    tampered.back() = tampered.back() == '0' ? '1' : '0';
    CHECK(parse_claim_line(tampered, kSecret, kNow).error == "bad hmac");
    CHECK(parse_claim_line(claim("p1", "h2", kNow, "another-secret-16b"), kSecret, kNow).error == "bad hmac");
    // The signature covers the host: the same hmac with another host is refused.
    std::string moved = line;
    moved.replace(moved.find(" h2 "), 4, " h3 ");
    CHECK(parse_claim_line(moved, kSecret, kNow).error == "bad hmac");
  }
  SECTION("stale or future times") {
    CHECK(parse_claim_line(claim("p1", "h2", kNow - 121), kSecret, kNow).error == "stale time");
    CHECK(parse_claim_line(claim("p1", "h2", kNow + 121), kSecret, kNow).error == "stale time");
  }
  SECTION("bad fields") {
    CHECK(parse_claim_line(claim("bad/uid", "h2", kNow), kSecret, kNow).error == "bad uid");
    CHECK(parse_claim_line(claim(std::string(65, 'u'), "h2", kNow), kSecret, kNow).error == "bad uid");
    CHECK(parse_claim_line(claim("p1", "H2", kNow), kSecret, kNow).error == "bad host");
    CHECK(parse_claim_line(claim("p1", std::string(33, 'h'), kNow), kSecret, kNow).error == "bad host");
    CHECK(parse_claim_line("claim p1 h2 12x34 " + std::string(64, 'a'), kSecret, kNow).error == "bad time");
    CHECK(parse_claim_line("claim p1 h2 -5 " + std::string(64, 'a'), kSecret, kNow).error == "bad time");
    CHECK_FALSE(parse_claim_line("claim p1 h2 1795515330", kSecret, kNow).claim);
    CHECK_FALSE(parse_claim_line("claim  p1 h2 1795515330 " + std::string(64, 'a'), kSecret, kNow).claim);
    CHECK_FALSE(parse_claim_line("owner h2 " + std::string(64, 'a'), kSecret, kNow).claim);
    CHECK_FALSE(parse_claim_line("", kSecret, kNow).claim);
  }
  SECTION("an overlong line") {
    CHECK(parse_claim_line(std::string(kMaxRegistryLine, 'c'), kSecret, kNow).error == "line too long");
  }
}

TEST_CASE("owner lines are bound to the uid asked about", "[uid_registry]") {
  const std::string line = chomp(owner_line(kSecret, "p01", "h3"));
  CHECK(line == "owner h3 " + hmac_sha256_hex(kSecret, "owner p01 h3"));
  CHECK(parse_owner_line(line, kSecret, "p01") == std::optional<std::string>("h3"));
  CHECK_FALSE(parse_owner_line(line, kSecret, "p02"));              // an answer about another uid
  CHECK_FALSE(parse_owner_line(line, "another-secret-16b", "p01"));  // another cluster's answer
  CHECK_FALSE(parse_owner_line("error bad hmac", kSecret, "p01"));
  CHECK_FALSE(parse_owner_line("owner H3 " + hmac_sha256_hex(kSecret, "owner p01 H3"), kSecret, "p01"));
  CHECK_FALSE(parse_owner_line(line + " extra", kSecret, "p01"));
  CHECK(rfbsim::manager::error_line("bad\nthing\x01") == "error bad?thing?\n");
}

TEST_CASE("uid_homes keeps the first home of a uid, across a reopen", "[uid_registry][session_index]") {
  rfbsim::test::ScratchDir dir("uid_homes");
  const std::string path = (dir.path() / "sessions.db").string();
  const rfbsim::manager::WallTime when{std::chrono::seconds(kNow)};
  {
    SessionIndex index(path);
    CHECK_FALSE(index.uid_home("p01"));
    CHECK(index.claim_uid_home("p01", "h2", when) == "h2");
    CHECK(index.claim_uid_home("p01", "h1", when) == "h2");  // the record never changes
    CHECK(index.claim_uid_home("p02", "h1", when) == "h1");
  }
  SessionIndex reopened(path);
  CHECK(reopened.uid_home("p01") == std::optional<std::string>("h2"));
  CHECK(reopened.claim_uid_home("p01", "h3", when) == "h2");
}

TEST_CASE("cluster settings fit together or name what is wrong", "[uid_registry][config]") {
  using Strings = std::vector<std::string>;
  const Strings cluster = {"--host-id", "h2", "--cluster-peers", "h1=10.0.0.1:7001,h2=10.0.0.2:7002,h3=db.example:7003",
                           "--cluster-secret-file", "/run/secret"};
  const auto good = parse_manager_args(cluster);
  REQUIRE(good.error.empty());
  REQUIRE(good.config.cluster_peers.size() == 3);
  CHECK(good.config.cluster_peers[2].id == "h3");
  CHECK(good.config.cluster_peers[2].address == "db.example");
  CHECK(good.config.cluster_peers[2].port == 7003);
  CHECK(good.config.path_prefix == "/h2");  // the balancer's route to this host

  auto with = [&](Strings more) {
    Strings args = cluster;
    args.insert(args.end(), more.begin(), more.end());
    return parse_manager_args(args).error;
  };
  CHECK(with({"--registry-port", "7002"}).empty());
  CHECK(with({"--registry-port", "7005"}).find("differs") != std::string::npos);
  CHECK(with({"--registry-bind", "10.0.0.2"}).empty());
  CHECK(with({"--registry-bind", "db.example"}).find("IPv4") != std::string::npos);
  CHECK(with({"--host-id", "h9"}).find("not one of cluster_peers") != std::string::npos);
  CHECK(parse_manager_args({"--host-id", "h1", "--cluster-peers", "h1=a:1"}).error.find("cluster_secret_file") !=
        std::string::npos);
  CHECK(parse_manager_args({"--cluster-peers", "h1=a:1", "--cluster-secret-file", "s"}).error.find("host_id") !=
        std::string::npos);
  CHECK(parse_manager_args({"--registry-port", "7001"}).error.find("need cluster_peers") != std::string::npos);
  for (const std::string bad : {"h1", "h1=a", "h1=:7", "H1=a:7", "h1=a:0", "h1=a:70000", "h1=a b:7", "=a:7"}) {
    CAPTURE(bad);
    CHECK(parse_manager_args({"--cluster-peers", bad}).error.find("ID=ADDRESS:PORT") != std::string::npos);
  }
  CHECK(parse_manager_args({"--cluster-peers", "h1=a:1,h1=b:2"}).error.find("twice") != std::string::npos);
}
