// SPDX-License-Identifier: GPL-2.0-or-later
#include "rfbsim/log.hpp"

#include <catch2/catch.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

// Captures the sink's lines for one test and puts everything back after it.
struct CapturedLog {
  std::vector<std::string> lines;
  CapturedLog() {
    rfbsim::log::set_sink([this](std::string_view line) { lines.emplace_back(line); });
    rfbsim::log::set_level(rfbsim::log::Level::kInfo);
  }
  ~CapturedLog() {
    rfbsim::log::flush_suppressed();
    rfbsim::log::set_sink({});
    rfbsim::log::set_level(rfbsim::log::Level::kInfo);
    rfbsim::log::set_rate_limit({});
  }
};

}  // namespace

TEST_CASE("log: a line is [tag] text, without the format's own newline, and the level filters") {
  CapturedLog log;
  rfbsim::log::info("manager", "session %d started\n", 7);
  rfbsim::log::debug("manager", "not shown at info");
  rfbsim::log::set_level(rfbsim::log::Level::kError);
  rfbsim::log::warn("manager", "not shown at error");
  rfbsim::log::error("manager", "shown: %s", "disk full");
  CHECK(log.lines == std::vector<std::string>{"[manager] session 7 started", "[manager] shown: disk full"});
}

TEST_CASE("log: level names parse, and nothing else does") {
  rfbsim::log::Level level = rfbsim::log::Level::kInfo;
  CHECK(rfbsim::log::parse_level("debug", level));
  CHECK(level == rfbsim::log::Level::kDebug);
  CHECK(rfbsim::log::parse_level("error", level));
  CHECK(level == rfbsim::log::Level::kError);
  CHECK_FALSE(rfbsim::log::parse_level("verbose", level));
  CHECK_FALSE(rfbsim::log::parse_level("", level));
}

TEST_CASE("log: a long line is written whole") {
  CapturedLog log;
  const std::string long_text(3000, 'x');
  rfbsim::log::info("t", "%s|", long_text.c_str());
  REQUIRE(log.lines.size() == 1);
  CHECK(log.lines[0] == "[t] " + long_text + "|");
}

TEST_CASE("log: past its budget a kind of line is counted, and one line per period says how many") {
  CapturedLog log;
  rfbsim::log::set_rate_limit({3, std::chrono::milliseconds(200)});
  for (int i = 0; i < 1000; ++i) rfbsim::log::limited(rfbsim::log::Level::kWarn, "bad-request", "manager", "bad %d", i);
  // Another kind has a budget of its own.
  rfbsim::log::limited(rfbsim::log::Level::kWarn, "takeover", "manager", "took over");
  CHECK(log.lines == std::vector<std::string>{"[manager] bad 0", "[manager] bad 1", "[manager] bad 2",
                                              "[manager] took over"});
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  rfbsim::log::limited(rfbsim::log::Level::kWarn, "bad-request", "manager", "bad again");
  REQUIRE(log.lines.size() == 6);
  CHECK(log.lines[4] == "[manager] 997 more like this suppressed (bad-request)");
  CHECK(log.lines[5] == "[manager] bad again");
}

TEST_CASE("log: suppressed counts are written at a flush, and lines from many threads stay whole") {
  CapturedLog log;
  rfbsim::log::set_rate_limit({2, std::chrono::hours(1)});
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([] {
      for (int i = 0; i < 100; ++i) rfbsim::log::limited(rfbsim::log::Level::kInfo, "flood", "sim", "connection %d", i);
    });
  }
  for (auto& thread : threads) thread.join();
  rfbsim::log::flush_suppressed();
  REQUIRE(log.lines.size() == 3);
  CHECK(log.lines[2] == "[sim] 398 more like this suppressed (flood)");
}

TEST_CASE("log: a level set by name takes effect, and a bad name changes nothing") {
  CapturedLog log;
  CHECK(rfbsim::log::set_level(std::string_view("warn")));
  CHECK(rfbsim::log::level() == rfbsim::log::Level::kWarn);
  CHECK_FALSE(rfbsim::log::set_level(std::string_view("loud")));
  CHECK(rfbsim::log::level() == rfbsim::log::Level::kWarn);
  rfbsim::log::info("t", "hidden");
  rfbsim::log::warn("t", "shown");
  CHECK(log.lines == std::vector<std::string>{"[t] shown"});
}
