// SPDX-License-Identifier: GPL-2.0-or-later
// The ready pipe's lines: each writer's exact bytes, read back by the one parser, and malformed lines refused.
#include <catch2/catch.hpp>

#include "contract/ready_line.hpp"

namespace contract = rfbsim::contract;

namespace {

// `line` without its '\n' (the reader splits on it), parsed.
contract::ReadyLineParse read_back(std::string line) {
  REQUIRE(!line.empty());
  REQUIRE(line.back() == '\n');
  line.pop_back();
  return contract::parse_ready_line(line);
}

// The value of type T that `line` parses to; fails the test when it parses to none or another.
template <typename T>
T parsed_as(const std::string& line) {
  const contract::ReadyLineParse parsed = contract::parse_ready_line(line);
  INFO(line << ": " << parsed.error);
  REQUIRE(parsed.line);
  const T* value = std::get_if<T>(&*parsed.line);
  REQUIRE(value != nullptr);
  return *value;
}

}  // namespace

TEST_CASE("each writer writes the bytes the programs always wrote") {
  CHECK(contract::ready_port_line(5901) == "ready 5901\n");
  CHECK(contract::ready_unix_line("/run/rfbsim/s/1.sock") == "ready unix /run/rfbsim/s/1.sock\n");
  CHECK(contract::x11_display_line(7) == "x11 display 7\n");
  CHECK(contract::outcome_line(contract::TaskEnd::kCompleted) == "outcome completed\n");
  CHECK(contract::outcome_line(contract::TaskEnd::kTimeout) == "outcome timeout\n");
  CHECK(contract::outcome_line(contract::TaskEnd::kWatched) == "outcome watched\n");
  CHECK(contract::data_incomplete_line("disk full") == "data incomplete reason=disk full\n");
}

TEST_CASE("what each writer writes reads back as it was") {
  const auto port = read_back(contract::ready_port_line(65535));
  REQUIRE(port.line);
  CHECK(std::get<contract::ReadyPort>(*port.line).port == 65535);
  const auto unix_socket = read_back(contract::ready_unix_line("/tmp/a b/s.sock"));
  REQUIRE(unix_socket.line);
  CHECK(std::get<contract::ReadyUnix>(*unix_socket.line).path == "/tmp/a b/s.sock");
  const auto display = read_back(contract::x11_display_line(0));
  REQUIRE(display.line);
  CHECK(std::get<contract::X11Display>(*display.line).display == 0);
  for (const auto end : {contract::TaskEnd::kCompleted, contract::TaskEnd::kTimeout, contract::TaskEnd::kWatched}) {
    const auto outcome = read_back(contract::outcome_line(end));
    REQUIRE(outcome.line);
    CHECK(std::get<contract::TaskOutcomeLine>(*outcome.line).end == end);
  }
  const auto incomplete = read_back(contract::data_incomplete_line("events.jsonl: No space left on device"));
  REQUIRE(incomplete.line);
  CHECK(std::get<contract::DataIncomplete>(*incomplete.line).reason == "events.jsonl: No space left on device");
  const auto stream = read_back(contract::stream_line(contract::StreamReport{1, "tight", 12.5, 30, 80, std::nullopt}));
  REQUIRE(stream.line);
  CHECK(std::get<contract::StreamReport>(*stream.line).clients == 1);
}

TEST_CASE("a data failure without a reason reads as unknown, and a long reason is cut") {
  CHECK(parsed_as<contract::DataIncomplete>("data incomplete").reason == "unknown");
  CHECK(parsed_as<contract::DataIncomplete>("data incomplete reason=").reason == "unknown");
  CHECK(parsed_as<contract::DataIncomplete>("data incomplete at=3 reason=x").reason == "x");
  CHECK(parsed_as<contract::DataIncomplete>("data incomplete reason=" + std::string(500, 'r')).reason ==
        std::string(contract::kMaxDataReason, 'r'));
}

TEST_CASE("malformed lines are refused with a reason") {
  for (const std::string line :
       {"", "ready", "ready ", "ready 0", "ready 65536", "ready -1", "ready +5", "ready  5", "ready 5 ", "ready 5\r",
        "ready 5x", "ready unix", "ready unix ", "ready unix /a\tb", "x11 display ", "x11 display -1",
        "x11 display 65536", "x11 display 1.5", "outcome", "outcome done", "outcome completed ", "outcome watched ", "outcome Watched", "outcome watch", "data incompleted",
        "stream", "stream clients=x", "hello"}) {
    const contract::ReadyLineParse parsed = contract::parse_ready_line(line);
    INFO("'" << line << "'");
    CHECK_FALSE(parsed.line.has_value());
    CHECK_FALSE(parsed.error.empty());
  }
}

TEST_CASE("a replay's watched outcome reads back, and the older outcomes keep their names") {
  CHECK(parsed_as<contract::TaskOutcomeLine>("outcome watched").end == contract::TaskEnd::kWatched);
  CHECK(parsed_as<contract::TaskOutcomeLine>("outcome completed").end == contract::TaskEnd::kCompleted);
  CHECK(parsed_as<contract::TaskOutcomeLine>("outcome timeout").end == contract::TaskEnd::kTimeout);
  CHECK(std::string(contract::task_end_name(contract::TaskEnd::kWatched)) == "watched");
  CHECK(std::string(contract::task_end_name(contract::TaskEnd::kCompleted)) == "completed");
  CHECK(std::string(contract::task_end_name(contract::TaskEnd::kTimeout)) == "timeout");
}
