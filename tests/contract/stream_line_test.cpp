// SPDX-License-Identifier: GPL-2.0-or-later
// The ready pipe's stream line: every key read, unknown ones ignored, bad ones refused whole, and what the writer
// writes read back as it was.
#include <catch2/catch.hpp>

#include "contract/stream_line.hpp"

using rfbsim::contract::is_stream_line;
using rfbsim::contract::parse_stream_line;
using rfbsim::contract::StreamParse;

namespace {

// The error for `line`, or "" when it parses.
std::string error_of(const std::string& line) { return parse_stream_line(line).error; }

}  // namespace

TEST_CASE("a stream line gives every value it carries") {
  const StreamParse parsed = parse_stream_line("stream codec=h264 rtt_ms=52.3 fps=29.7 quality=80 clients=1");
  REQUIRE(parsed.error.empty());
  REQUIRE(parsed.report);
  CHECK(parsed.report->clients == 1);
  CHECK(parsed.report->codec == "h264");
  CHECK(parsed.report->rtt_ms == 52.3);
  CHECK(parsed.report->fps == 29.7);
  CHECK(parsed.report->quality == 80);
}

TEST_CASE("an unmeasured round trip (-1), and keys left out, stay unknown") {
  const auto tight = parse_stream_line("stream codec=tight rtt_ms=-1 fps=0 quality=80 clients=2").report;
  REQUIRE(tight);
  CHECK_FALSE(tight->rtt_ms);
  CHECK(tight->fps == 0.0);
  CHECK(tight->clients == 2);
  const auto nobody = parse_stream_line("stream clients=0").report;
  REQUIRE(nobody);
  CHECK(nobody->clients == 0);
  CHECK(nobody->codec.empty());
  CHECK_FALSE(nobody->rtt_ms);
  CHECK_FALSE(nobody->fps);
  CHECK_FALSE(nobody->quality);
  CHECK(parse_stream_line("stream rtt_ms=-1.0 clients=1").report->rtt_ms == std::nullopt);
  CHECK(parse_stream_line("stream rtt_ms=0 clients=1").report->rtt_ms == 0.0);
}

TEST_CASE("keys come in any order, unknown keys are ignored, and spaces are forgiven") {
  const auto report = parse_stream_line("stream clients=1 mbit=4.5 codec=tight future=x=y fps=30").report;
  REQUIRE(report);
  CHECK(report->codec == "tight");
  CHECK(report->fps == 30.0);
  CHECK(parse_stream_line("stream  clients=1   fps=2 \r").report->fps == 2.0);
  // An unknown key's value is not checked: a newer sim_rfb may say anything there.
  CHECK(error_of("stream clients=1 note=") == "");
}

TEST_CASE("bad values are refused whole, naming the key") {
  CHECK(error_of("stream codec=H264 clients=1") == "bad value 'H264' for codec");
  CHECK(error_of("stream codec= clients=1") == "bad value '' for codec");
  CHECK(error_of("stream codec=h264\"} clients=1") == "bad value 'h264\"}' for codec");
  CHECK(error_of("stream codec=abcdefghijklmnopq clients=1") == "bad value 'abcdefghijklmnopq' for codec");
  CHECK(error_of("stream rtt_ms=-2 clients=1") == "bad value '-2' for rtt_ms");
  CHECK(error_of("stream rtt_ms=-0.5 clients=1") == "bad value '-0.5' for rtt_ms");
  CHECK(error_of("stream rtt_ms=nan clients=1") == "bad value 'nan' for rtt_ms");
  CHECK(error_of("stream rtt_ms=inf clients=1") == "bad value 'inf' for rtt_ms");
  CHECK(error_of("stream rtt_ms=1e3 clients=1") == "bad value '1e3' for rtt_ms");
  CHECK(error_of("stream rtt_ms=600000.1 clients=1") == "bad value '600000.1' for rtt_ms");
  CHECK(error_of("stream fps=-1 clients=1") == "bad value '-1' for fps");
  CHECK(error_of("stream fps=1000.5 clients=1") == "bad value '1000.5' for fps");
  CHECK(error_of("stream fps=+3 clients=1") == "bad value '+3' for fps");
  CHECK(error_of("stream quality=101 clients=1") == "bad value '101' for quality");
  CHECK(error_of("stream quality=8.5 clients=1") == "bad value '8.5' for quality");
  CHECK(error_of("stream clients=-1") == "bad value '-1' for clients");
  CHECK(error_of("stream clients=one") == "bad value 'one' for clients");
  CHECK(error_of("stream clients=99999999999") == "bad value '99999999999' for clients");
  // Nothing of a refused line is taken.
  CHECK_FALSE(parse_stream_line("stream codec=h264 fps=30 quality=900 clients=1").report);
}

TEST_CASE("lines that are not key=value pairs, repeat a key or lack clients are refused") {
  CHECK(error_of("stream") == "no clients=N");
  CHECK(error_of("stream codec=h264 fps=30") == "no clients=N");
  CHECK(error_of("stream clients=1 fps") == "'fps' is not key=value");
  CHECK(error_of("stream =1 clients=1") == "'=1' is not key=value");
  CHECK(error_of("stream clients=1 clients=2") == "key 'clients' given twice");
  CHECK(error_of("stream clients=1 x=1 x=2") == "key 'x' given twice");
  CHECK(error_of("streams clients=1") == "not a stream line");
  CHECK(error_of("ready 5901") == "not a stream line");
  CHECK(error_of("") == "not a stream line");
}

TEST_CASE("a stream line is told from the pipe's other lines by its first word") {
  CHECK(is_stream_line("stream clients=0"));
  CHECK(is_stream_line("stream"));
  CHECK_FALSE(is_stream_line("streaming clients=0"));
  CHECK_FALSE(is_stream_line("outcome completed"));
  CHECK_FALSE(is_stream_line(" stream clients=0"));
}

TEST_CASE("arbitrary bytes never crash the parser") {
  // A tiny fuzz: every line made of a few pieces that parsers trip on.
  const char* pieces[] = {"stream", " ", "=", "clients", "codec", "rtt_ms", "fps", "quality", "-1", "1.5", "3", "",
                          "\r", "\x01", "\xff", "99999999999999999999", "=="};
  std::size_t parsed = 0;
  for (const char* a : pieces) {
    for (const char* b : pieces) {
      for (const char* c : pieces) {
        for (const char* d : pieces) {
          const std::string line = std::string("stream ") + a + b + c + d;
          const StreamParse result = parse_stream_line(line);
          CHECK(result.report.has_value() == result.error.empty());
          if (result.report) ++parsed;
        }
      }
    }
  }
  CHECK(parsed > 0);
}

TEST_CASE("the writer gives sim_rfb's exact bytes") {
  using rfbsim::contract::StreamReport;
  using rfbsim::contract::stream_line;
  CHECK(stream_line(StreamReport{}) == "stream clients=0\n");
  CHECK(stream_line(StreamReport{1, "tight", 12.54, 29.76, 80, std::nullopt}) ==
        "stream codec=tight rtt_ms=12.5 fps=29.8 quality=80 clients=1\n");
  // Unmeasured round trip, no codec name, then values beyond their bounds: clamped, never a longer line.
  CHECK(stream_line(StreamReport{2, "", std::nullopt, 0.0, 60, std::nullopt}) == "stream rtt_ms=-1 fps=0.0 quality=60 clients=2\n");
  CHECK(stream_line(StreamReport{123456, "Not A Codec", 1e12, 1.0 / 0.0, 500, std::nullopt}) ==
        "stream rtt_ms=600000.0 fps=0.0 quality=100 clients=9999\n");
  // A lossless encoding has no quality: the key is left out rather than written as 0.
  CHECK(stream_line(StreamReport{1, "zrle", 3.0, 15.0, std::nullopt, std::nullopt}) == "stream codec=zrle rtt_ms=3.0 fps=15.0 clients=1\n");
  // The viewer's own request (TigerVNC's -QualityLevel=3), after the quality in use; clamped like it.
  CHECK(stream_line(StreamReport{1, "tight", 3.1, 30.0, 42, 42}) ==
        "stream codec=tight rtt_ms=3.1 fps=30.0 quality=42 requested=42 clients=1\n");
  // The longest line there can be stays under 100 bytes (one atomic write to a pipe).
  CHECK(stream_line(StreamReport{9999, "abcdefghijklmnop", 1e12, 1e12, 500, 500}) ==
        "stream codec=abcdefghijklmnop rtt_ms=600000.0 fps=1000.0 quality=100 requested=100 clients=9999\n");
  CHECK(stream_line(StreamReport{9999, "abcdefghijklmnop", 1e12, 1e12, 500, 500}).size() < 100);
}

TEST_CASE("what the writer writes reads back as it was") {
  using rfbsim::contract::StreamReport;
  for (const StreamReport& written : {StreamReport{1, "h264", 52.3, 29.7, 80, std::nullopt}, StreamReport{3, "", std::nullopt, 0.5, 1, std::nullopt},
                                      StreamReport{9999, "tight", 0.0, 1000.0, 100, std::nullopt},
                                      StreamReport{1, "zrle", 2.5, 15.0, std::nullopt, std::nullopt},
                                      StreamReport{1, "tight", 3.1, 30.0, 42, 42}}) {
    std::string line = rfbsim::contract::stream_line(written);
    REQUIRE(line.back() == '\n');
    line.pop_back();
    const StreamParse read = parse_stream_line(line);
    REQUIRE(read.report);
    CHECK(read.report->clients == written.clients);
    CHECK(read.report->codec == written.codec);
    CHECK(read.report->rtt_ms == written.rtt_ms);
    CHECK(read.report->fps == written.fps);
    CHECK(read.report->quality == written.quality);
    CHECK(read.report->requested == written.requested);
  }
  CHECK(parse_stream_line("stream quality=42 requested=101 clients=1").error == "bad value '101' for requested");
  CHECK(parse_stream_line("stream clients=10000").report == std::nullopt);  // the writer's bound is the reader's
}
