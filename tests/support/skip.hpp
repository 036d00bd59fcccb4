// SPDX-License-Identifier: GPL-2.0-or-later
// RFBSIM_SKIP(why): ends a test whose real part cannot run here (a program, a library feature or a privilege is
// missing) so that ctest reports it Skipped and names what is missing, never Passed. With RFBSIM_NO_SKIP=1 in the
// environment (scripts/test.sh and CI, which install everything the tests need) the same test fails instead.
// ctest tells a skip by the marker line: rfbsim_add_catch_tests (cmake/RfbsimTesting.cmake) sets every Catch
// test's SKIP_REGULAR_EXPRESSION to it.
#pragma once

#include <catch2/catch.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace rfbsim::test {

/// The start of the line that marks a skip (cmake/RfbsimTesting.cmake's RFBSIM_SKIP_MARKER is the same text).
inline constexpr const char* kSkipMarker = "RFBSIM-SKIPPED:";

/// Whether a test that cannot run its real part must fail rather than skip (RFBSIM_NO_SKIP=1).
inline bool skips_are_failures() {
  const char* value = std::getenv("RFBSIM_NO_SKIP");
  return value != nullptr && std::string_view(value) == "1";
}

/// Prints the skip marker line with `why`.
inline void print_skip(const std::string& why) {
  std::printf("%s %s\n", kSkipMarker, why.c_str());
  std::fflush(stdout);
}

}  // namespace rfbsim::test

/// In a TEST_CASE's body: skips the rest of the test, naming `why` (what is missing and how to get it), or fails
/// the test with the same words under RFBSIM_NO_SKIP=1.
#define RFBSIM_SKIP(why)                                                                                  \
  do {                                                                                                    \
    const std::string rfbsim_skip_why_ = (why);                                                           \
    if (::rfbsim::test::skips_are_failures()) FAIL("cannot run here (RFBSIM_NO_SKIP=1): " << rfbsim_skip_why_); \
    ::rfbsim::test::print_skip(rfbsim_skip_why_);                                                         \
    return;                                                                                               \
  } while (false)
