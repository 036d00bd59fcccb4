// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <cctype>
#include <stdexcept>

#include "admission/link_signature.hpp"

using rfbsim::manager::canonical_link_text;
using rfbsim::manager::hmac_sha256_hex;
using rfbsim::manager::link_signature_valid;
using rfbsim::manager::parse_query;
using rfbsim::manager::QueryParams;
using rfbsim::manager::sign_query;

namespace {

const std::string kSecret = "0123456789abcdef";
// HMAC-SHA256(kSecret, "scenario=lab&uid=p01"), computed with Python's hmac module.
const std::string kLabP01Sig = "04c4bbfdc88b77a3205f8e5668103d611e55545773c9bb1742570e4c29ebd76d";

QueryParams parsed(const std::string& query) {
  std::string error;
  const auto params = parse_query(query, error);
  if (!params) throw std::invalid_argument(error);
  return *params;
}

}  // namespace

TEST_CASE("the canonical text sorts by name and leaves sig out") {
  CHECK(canonical_link_text({{"uid", "p01"}, {"scenario", "lab"}}) == "scenario=lab&uid=p01");
  CHECK(canonical_link_text({{"uid", "p01"}, {"sig", "abc"}, {"crowd", "3"}, {"scenario", "lab"}}) ==
        "crowd=3&scenario=lab&uid=p01");
  CHECK(canonical_link_text({{"sig", "abc"}}).empty());
  CHECK(canonical_link_text({}).empty());
}

TEST_CASE("the canonical text sorts in byte order and uses decoded values") {
  // Upper case sorts before lower case, '_' (0x5f) between them.
  CHECK(canonical_link_text({{"b", "1"}, {"_", "2"}, {"a", "3"}, {"B", "4"}}) == "B=4&_=2&a=3&b=1");
  CHECK(canonical_link_text(parsed("uid=p+01&scenario=%6cab")) == "scenario=lab&uid=p 01");
}

TEST_CASE("hmac_sha256_hex matches RFC 4231 test case 2") {
  CHECK(hmac_sha256_hex("Jefe", "what do ya want for nothing?") ==
        "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843");
}

TEST_CASE("hmac_sha256_hex of an empty text and an empty key") {
  CHECK(hmac_sha256_hex("", "") == "b613679a0814d9ec772f95d778c35fc5ff1697c493715653c6c712144292c5ad");
  CHECK(hmac_sha256_hex(kSecret, "scenario=lab&uid=p01") == kLabP01Sig);
}

TEST_CASE("a link signed with the secret is valid") {
  CHECK(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}, {"sig", kLabP01Sig}}, kSecret));
}

TEST_CASE("the parameters of a signed link may come in any order") {
  CHECK(link_signature_valid({{"sig", kLabP01Sig}, {"scenario", "lab"}, {"uid", "p01"}}, kSecret));
  CHECK(link_signature_valid(parsed("scenario=lab&sig=" + kLabP01Sig + "&uid=p01"), kSecret));
}

TEST_CASE("a link without sig or with a wrong one is refused") {
  SECTION("missing sig") { CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}}, kSecret)); }
  SECTION("empty sig") { CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}, {"sig", ""}}, kSecret)); }
  SECTION("one hex digit changed") {
    std::string sig = kLabP01Sig;
    sig[10] = sig[10] == '0' ? '1' : '0';
    CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}, {"sig", sig}}, kSecret));
  }
  SECTION("upper-case hex") {
    std::string sig = kLabP01Sig;
    for (char& ch : sig) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}, {"sig", sig}}, kSecret));
  }
  SECTION("truncated and extended") {
    CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}, {"sig", kLabP01Sig.substr(0, 63)}}, kSecret));
    CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}, {"sig", kLabP01Sig + "0"}}, kSecret));
  }
  SECTION("another secret") {
    CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}, {"sig", kLabP01Sig}}, "0123456789abcdeF"));
  }
}

TEST_CASE("changing, adding or removing a parameter breaks the signature") {
  CHECK_FALSE(link_signature_valid({{"uid", "p02"}, {"scenario", "lab"}, {"sig", kLabP01Sig}}, kSecret));
  CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "warehouse"}, {"sig", kLabP01Sig}}, kSecret));
  CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"scenario", "lab"}, {"seed", "1"}, {"sig", kLabP01Sig}}, kSecret));
  CHECK_FALSE(link_signature_valid({{"uid", "p01"}, {"sig", kLabP01Sig}}, kSecret));
}

TEST_CASE("sign_query appends the signature of the decoded parameters") {
  CHECK(sign_query("uid=p01&scenario=lab", kSecret) == "uid=p01&scenario=lab&sig=" + kLabP01Sig);
  // Encoded spellings of the same values sign the same text.
  CHECK(sign_query("uid=p%301&scenario=l%61b", kSecret) == "uid=p%301&scenario=l%61b&sig=" + kLabP01Sig);
  CHECK(sign_query("", kSecret) == "sig=" + hmac_sha256_hex(kSecret, ""));
}

TEST_CASE("a signed query parses back into a valid link") {
  const std::string signed_query = sign_query("crowd=3&uid=p+01&scenario=lab", kSecret);
  CHECK(signed_query ==
        "crowd=3&uid=p+01&scenario=lab&sig=8054b7dc5c38d1d5b50626621d7185172bd5b0b55a262f58e7c1dc4fae9287be");
  CHECK(link_signature_valid(parsed(signed_query), kSecret));
  CHECK_FALSE(link_signature_valid(parsed(signed_query), "another secret!!"));
}

TEST_CASE("sign_query refuses a query that already has sig or does not parse") {
  CHECK_THROWS_WITH(sign_query("uid=p01&sig=abc", kSecret), "the query already has a sig");
  CHECK_THROWS_AS(sign_query("uid=p01&&scenario=lab", kSecret), std::invalid_argument);
  CHECK_THROWS_WITH(sign_query("uid", kSecret), "malformed parameter 'uid' (expected name=value)");
}
