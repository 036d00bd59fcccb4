// SPDX-License-Identifier: GPL-2.0-or-later
// MCAP records byte by byte against the specification's tables (https://mcap.dev/spec): opcode, uint64
// content length, fields little-endian, Strings and Maps prefixed with their uint32 byte length.
#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "ros/mcap/mcap_records.hpp"

using namespace rfbsim::ros::mcap;
using Bytes = std::vector<std::uint8_t>;

TEST_CASE("a Header record: opcode 1, length, profile and library as Strings") {
  Bytes out;
  append_header(out, "ros2", "x");
  CHECK(out == Bytes{0x01, 13, 0, 0, 0, 0, 0, 0, 0,  // opcode, content length 4+4+4+1
                     4, 0, 0, 0, 'r', 'o', 's', '2', 1, 0, 0, 0, 'x'});
}

TEST_CASE("a Message record: channel, sequence, log and publish times, then the data unprefixed") {
  Bytes out;
  const std::uint8_t data[2] = {0xAA, 0xBB};
  append_message(out, 0x0102, 7, 0x10, 0x20, data, 2);
  CHECK(out == Bytes{0x05, 24, 0, 0, 0, 0, 0, 0, 0,  // 2+4+8+8 + 2
                     0x02, 0x01, 7, 0, 0, 0,         //
                     0x10, 0, 0, 0, 0, 0, 0, 0,      //
                     0x20, 0, 0, 0, 0, 0, 0, 0,      //
                     0xAA, 0xBB});
}

TEST_CASE("a Channel record carries its metadata as a Map<string, string> with a byte length") {
  Bytes out;
  append_channel(out, Channel{3, 1, "/t", "cdr", {{"k", "vv"}}});
  CHECK(out == Bytes{0x04, 32, 0, 0, 0, 0, 0, 0, 0,  // 2+2+(4+2)+(4+3)+(4+4+1+4+2)
                     3, 0, 1, 0,                     // id, schema_id
                     2, 0, 0, 0, '/', 't',           //
                     3, 0, 0, 0, 'c', 'd', 'r',      //
                     11, 0, 0, 0,                    // map byte length
                     1, 0, 0, 0, 'k', 2, 0, 0, 0, 'v', 'v'});
}

TEST_CASE("a MessageIndex record: channel, then an Array of (log_time, offset) with its byte length") {
  Bytes out;
  append_message_index(out, 2, {{5, 0}, {6, 40}});
  CHECK(out == Bytes{0x07, 38, 0, 0, 0, 0, 0, 0, 0,  // 2 + 4 + 2*16
                     2, 0, 32, 0, 0, 0,              //
                     5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                     6, 0, 0, 0, 0, 0, 0, 0, 40, 0, 0, 0, 0, 0, 0, 0});
}

TEST_CASE("SummaryOffset, DataEnd and the Footer's fixed layouts") {
  Bytes out;
  append_summary_offset(out, Opcode::kChunkIndex, 0x1000, 0x20);
  append_data_end(out, 0xDEADBEEF);
  append_footer_prefix(out, 0x30, 0x40);
  CHECK(out == Bytes{0x0E, 17, 0, 0, 0, 0, 0, 0, 0,  // group_opcode, group_start, group_length
                     0x08, 0x00, 0x10, 0, 0, 0, 0, 0, 0, 0x20, 0, 0, 0, 0, 0, 0, 0,  //
                     0x0F, 4, 0, 0, 0, 0, 0, 0, 0, 0xEF, 0xBE, 0xAD, 0xDE,            //
                     0x02, 20, 0, 0, 0, 0, 0, 0, 0,  // the Footer's length counts the CRC to come
                     0x30, 0, 0, 0, 0, 0, 0, 0, 0x40, 0, 0, 0, 0, 0, 0, 0});
}

TEST_CASE("CRC-32 is the zlib polynomial: the check value of \"123456789\", in one piece or two") {
  const std::string text = "123456789";
  const auto* p = reinterpret_cast<const std::uint8_t*>(text.data());
  CHECK(crc32_update(0, p, text.size()) == 0xCBF43926u);
  CHECK(crc32_update(crc32_update(0, p, 4), p + 4, 5) == 0xCBF43926u);
}
