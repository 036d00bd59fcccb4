// SPDX-License-Identifier: GPL-2.0-or-later
// ConnectionLimits: per-address and total caps on open connections.
#include "http/connection_limits.hpp"

#include <catch2/catch.hpp>

using rfbsim::manager::ConnectionLimits;

TEST_CASE("one address may hold its cap of connections and no more, others are unaffected") {
  ConnectionLimits limits(2, 10);
  CHECK(limits.try_open("a"));
  CHECK(limits.try_open("a"));
  CHECK_FALSE(limits.try_open("a"));
  CHECK(limits.open("a") == 2);
  CHECK(limits.try_open("b"));
  limits.closed("a");
  CHECK(limits.try_open("a"));
  CHECK(limits.open_total() == 3);
}

TEST_CASE("the total cap holds across addresses") {
  ConnectionLimits limits(5, 3);
  CHECK(limits.try_open("a"));
  CHECK(limits.try_open("b"));
  CHECK(limits.try_open("c"));
  CHECK_FALSE(limits.try_open("d"));
  CHECK_FALSE(limits.try_open_uncapped("proxy"));
  limits.closed("b");
  CHECK(limits.try_open("d"));
}

TEST_CASE("a trusted front end counts in the total only") {
  ConnectionLimits limits(1, 100);
  for (int i = 0; i < 50; ++i) REQUIRE(limits.try_open_uncapped("proxy"));
  CHECK(limits.open("proxy") == 50);
  CHECK(limits.open_total() == 50);
}

TEST_CASE("closing what was never counted changes nothing, and addresses are forgotten at zero") {
  ConnectionLimits limits(0, 0);  // no caps
  limits.closed("ghost");
  CHECK(limits.open_total() == 0);
  CHECK(limits.try_open("a"));
  CHECK(limits.addresses() == 1);
  limits.closed("a");
  CHECK(limits.addresses() == 0);
  CHECK(limits.open_total() == 0);
}
