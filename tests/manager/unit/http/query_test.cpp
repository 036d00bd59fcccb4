// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "http/query.hpp"

using rfbsim::manager::parse_query;
using rfbsim::manager::percent_decode;
using rfbsim::manager::percent_encode;
using rfbsim::manager::QueryParams;
using rfbsim::manager::split_target;

TEST_CASE("percent_decode turns plus into a space and escapes into bytes") {
  CHECK(percent_decode("") == std::string());
  CHECK(percent_decode("plain-text_1.~") == std::string("plain-text_1.~"));
  CHECK(percent_decode("a+b") == std::string("a b"));
  CHECK(percent_decode("%41") == std::string("A"));
  CHECK(percent_decode("%4a%4A") == std::string("JJ"));
  CHECK(percent_decode("%2B") == std::string("+"));  // an escaped plus stays a plus
  CHECK(percent_decode("%2e%2e%2f") == std::string("../"));
  CHECK(percent_decode("%C3%A9") == std::string("\xC3\xA9"));  // UTF-8 bytes pass
}

TEST_CASE("percent_decode refuses bad and truncated escapes") {
  CHECK_FALSE(percent_decode("%"));
  CHECK_FALSE(percent_decode("%4"));
  CHECK_FALSE(percent_decode("a%4"));
  CHECK_FALSE(percent_decode("%zz"));
  CHECK_FALSE(percent_decode("%4g"));
  CHECK_FALSE(percent_decode("%g4"));
  CHECK_FALSE(percent_decode("%%41"));
}

TEST_CASE("percent_decode refuses decoded control characters") {
  CHECK_FALSE(percent_decode("%0a"));
  CHECK_FALSE(percent_decode("a%0Db"));
  CHECK_FALSE(percent_decode("%00"));
  CHECK_FALSE(percent_decode("%1f"));
  CHECK_FALSE(percent_decode("%7f"));
  CHECK_FALSE(percent_decode(std::string("a\nb")));  // raw ones too
  CHECK_FALSE(percent_decode(std::string("a\0b", 3)));
  CHECK(percent_decode("%20") == std::string(" "));  // a space is not a control character
}

TEST_CASE("percent_encode keeps unreserved characters and escapes the rest in upper case") {
  CHECK(percent_encode("aZ09-._~") == "aZ09-._~");
  CHECK(percent_encode("a b&c=d/e+") == "a%20b%26c%3Dd%2Fe%2B");
  CHECK(percent_encode("\xC3\xA9") == "%C3%A9");
  CHECK(percent_decode(percent_encode("x=1&y=2 3")) == std::string("x=1&y=2 3"));
}

TEST_CASE("parse_query keeps the parameters in the order given, decoded") {
  std::string error;
  const auto params = parse_query("uid=p%2001&scenario=lab&seed=7&note=a+b", error);
  REQUIRE(params);
  CHECK(error.empty());
  const QueryParams expected = {{"uid", "p 01"}, {"scenario", "lab"}, {"seed", "7"}, {"note", "a b"}};
  CHECK(*params == expected);
}

TEST_CASE("parse_query accepts an empty query and empty values") {
  std::string error;
  SECTION("empty query") {
    const auto params = parse_query("", error);
    REQUIRE(params);
    CHECK(params->empty());
  }
  SECTION("empty value") {
    const auto params = parse_query("a=", error);
    REQUIRE(params);
    CHECK(*params == QueryParams{{"a", ""}});
  }
  SECTION("an equals sign inside the value") {
    const auto params = parse_query("a=b=c", error);
    REQUIRE(params);
    CHECK(*params == QueryParams{{"a", "b=c"}});
  }
}

TEST_CASE("parse_query refuses malformed parameters and says which") {
  std::string error;
  SECTION("a name without a value") {
    CHECK_FALSE(parse_query("a", error));
    CHECK(error == "malformed parameter 'a' (expected name=value)");
  }
  SECTION("a value without a name") {
    CHECK_FALSE(parse_query("=b", error));
    CHECK(error == "malformed parameter '=b' (expected name=value)");
  }
  SECTION("an empty parameter between two") {
    CHECK_FALSE(parse_query("a=1&&b=2", error));
    CHECK(error == "malformed parameter '' (expected name=value)");
  }
  SECTION("a trailing ampersand") {
    CHECK_FALSE(parse_query("a=1&", error));
    CHECK(error == "malformed parameter '' (expected name=value)");
  }
  SECTION("bad percent-encoding") {
    CHECK_FALSE(parse_query("a=1&uid=%zz", error));
    CHECK(error == "bad percent-encoding in 'uid=%zz'");
  }
  SECTION("a decoded newline") {
    CHECK_FALSE(parse_query("uid=p01%0aX", error));
    CHECK(error == "bad percent-encoding in 'uid=p01%0aX'");
  }
}

TEST_CASE("parse_query refuses a parameter given twice, also when spelled differently") {
  std::string error;
  SECTION("same spelling") {
    CHECK_FALSE(parse_query("uid=a&seed=1&uid=b", error));
    CHECK(error == "parameter 'uid' given twice");
  }
  SECTION("one of them percent-encoded") {
    CHECK_FALSE(parse_query("uid=a&%75id=b", error));
    CHECK(error == "parameter 'uid' given twice");
  }
}

TEST_CASE("parse_query cuts long parameters short in its messages") {
  std::string error;
  CHECK_FALSE(parse_query(std::string(100, 'x'), error));
  CHECK(error == "malformed parameter '" + std::string(64, 'x') + "' (expected name=value)");
}

TEST_CASE("split_target separates the path from the query at the first question mark") {
  using Parts = std::pair<std::string_view, std::string_view>;
  CHECK(split_target("/start?uid=a&b=c") == Parts{"/start", "uid=a&b=c"});
  CHECK(split_target("/start") == Parts{"/start", ""});
  CHECK(split_target("/start?") == Parts{"/start", ""});
  CHECK(split_target("/a?b?c") == Parts{"/a", "b?c"});
  CHECK(split_target("") == Parts{"", ""});
}
