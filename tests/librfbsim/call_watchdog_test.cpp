// SPDX-License-Identifier: GPL-2.0-or-later
#include "call_watchdog.hpp"

#include <catch2/catch.hpp>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>

namespace {

using namespace std::chrono_literals;
using rfbsim::detail::CallWatchdog;

struct SocketPair {
  int ends[2] = {-1, -1};
  SocketPair() { REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM, 0, ends) == 0); }
  ~SocketPair() {
    ::close(ends[0]);
    ::close(ends[1]);
  }
};

}  // namespace

TEST_CASE("a call still running at its deadline has its socket shut down", "[call_watchdog]") {
  SocketPair pair;
  CallWatchdog watchdog;
  const auto started = std::chrono::steady_clock::now();
  watchdog.arm(pair.ends[0], started + 50ms);
  // A blocking read with nothing to read: only the watchdog can end it.
  char byte = 0;
  const auto n = ::read(pair.ends[0], &byte, 1);
  watchdog.disarm();
  CHECK(n == 0);  // end of stream: the socket was shut down
  CHECK(std::chrono::steady_clock::now() - started >= 50ms);
  CHECK(watchdog.fired() == 1);
}

TEST_CASE("a call that returns in time leaves its socket alone", "[call_watchdog]") {
  SocketPair pair;
  CallWatchdog watchdog;
  watchdog.arm(pair.ends[0], std::chrono::steady_clock::now() + 30ms);
  watchdog.disarm();
  std::this_thread::sleep_for(80ms);  // past the old deadline
  REQUIRE(::write(pair.ends[1], "x", 1) == 1);
  char byte = 0;
  CHECK(::read(pair.ends[0], &byte, 1) == 1);
  CHECK(byte == 'x');
  CHECK(watchdog.fired() == 0);
}

TEST_CASE("re-arming replaces the deadline of the previous call", "[call_watchdog]") {
  SocketPair first;
  SocketPair second;
  CallWatchdog watchdog;
  watchdog.arm(first.ends[0], std::chrono::steady_clock::now() + 30ms);
  watchdog.arm(second.ends[0], std::chrono::steady_clock::now() + 10s);
  std::this_thread::sleep_for(80ms);
  watchdog.forget(second.ends[0]);
  // Neither socket was touched: the first call's deadline died with it.
  REQUIRE(::write(first.ends[1], "a", 1) == 1);
  char byte = 0;
  CHECK(::read(first.ends[0], &byte, 1) == 1);
  CHECK(watchdog.fired() == 0);
}
