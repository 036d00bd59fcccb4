// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <algorithm>
#include <set>

#include "admission/tokens.hpp"

using rfbsim::manager::new_seed;
using rfbsim::manager::new_session_token;

TEST_CASE("a session token is 32 lower-case hex digits") {
  for (int i = 0; i < 100; ++i) {
    const std::string token = new_session_token();
    REQUIRE(token.size() == 32);
    for (const char ch : token) {
      INFO(token);
      CHECK(((ch >= '0' && ch <= '9') || (ch >= 'a' && ch <= 'f')));
    }
  }
}

TEST_CASE("1000 session tokens are all different and use every hex digit") {
  std::set<std::string> tokens;
  std::set<char> digits;
  for (int i = 0; i < 1000; ++i) {
    const std::string token = new_session_token();
    tokens.insert(token);
    digits.insert(token.begin(), token.end());
  }
  CHECK(tokens.size() == 1000);
  CHECK(digits.size() == 16);
}

TEST_CASE("drawn seeds fit 32 bits and differ") {
  std::set<std::uint64_t> seeds;
  std::uint64_t highest = 0;
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t seed = new_seed();
    CHECK(seed < (std::uint64_t{1} << 32));
    highest = std::max(highest, seed);
    seeds.insert(seed);
  }
  // 1000 draws from 2^32 values: a repeat has odds of about 1 in 10^4; the top byte gets used.
  CHECK(seeds.size() >= 999);
  CHECK(highest >= (std::uint64_t{1} << 24));
}
