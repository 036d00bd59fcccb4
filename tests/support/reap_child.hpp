// SPDX-License-Identifier: GPL-2.0-or-later
// Waiting for a child process a test started itself. Header-only, for Catch test files.
#pragma once

#include <sys/types.h>
#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <cerrno>

namespace rfbsim::test {

/// Waits for child `pid` (through EINTR) and returns its wait status; fails the test if it is not ours.
inline int reap_child(pid_t pid) {
  int status = 0;
  pid_t got = 0;
  do {
    got = ::waitpid(pid, &status, 0);
  } while (got < 0 && errno == EINTR);
  REQUIRE(got == pid);
  return status;
}

}  // namespace rfbsim::test
