// SPDX-License-Identifier: GPL-2.0-or-later
// ROS 2 CDR (classic CDR, little-endian, the CDR_LE encapsulation 00 01 00 00): each case writes known values
// and compares every byte with the layout the encoding defines: primitives aligned to their size counted
// from the byte after the header, strings as a length counting the NUL, the bytes and the NUL, sequences as
// a uint32 count and the elements.
#include <catch2/catch.hpp>

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "ros/mcap/cdr_writer.hpp"

using rfbsim::ros::CdrWriter;
using Bytes = std::vector<std::uint8_t>;

TEST_CASE("a fresh CDR message is the CDR_LE encapsulation header alone") {
  const CdrWriter cdr;
  CHECK(cdr.data() == Bytes{0x00, 0x01, 0x00, 0x00});
}

TEST_CASE("a float64 after a uint8 skips seven bytes, counted after the header") {
  CdrWriter cdr;
  cdr.u8(0xAB);
  cdr.f64(1.0);  // IEEE 754: 0x3FF0000000000000
  CHECK(cdr.data() == Bytes{0x00, 0x01, 0x00, 0x00,                           //
                            0xAB, 0, 0, 0, 0, 0, 0, 0,                        // uint8, 7 bytes of padding
                            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0x3F});  // float64 at offset 8
}

TEST_CASE("a string counts its NUL, and the next field aligns after it") {
  CdrWriter cdr;
  cdr.string("hi");  // offsets 0..6: length 3, 'h', 'i', NUL
  cdr.u32(7);        // offset 7 -> 8
  cdr.string("");    // an empty string is a length of 1 and the NUL
  cdr.u16(0x0102);   // offset 17 -> 18
  cdr.string("a");   // offset 20: length 2, 'a', NUL -> 26
  cdr.f64(-2.0);     // offset 26 -> 32: 0xC000000000000000
  CHECK(cdr.data() == Bytes{0x00, 0x01, 0x00, 0x00,                           //
                            0x03, 0x00, 0x00, 0x00, 'h', 'i', 0x00,            // "hi"
                            0x00,                                              // pad to 8
                            0x07, 0x00, 0x00, 0x00,                            // uint32 7
                            0x01, 0x00, 0x00, 0x00, 0x00,                      // ""
                            0x00,                                              // pad to 18
                            0x02, 0x01,                                        // uint16
                            0x02, 0x00, 0x00, 0x00, 'a', 0x00,                 // "a"
                            0x00, 0x00, 0x00, 0x00, 0x00, 0x00,                // pad to 32
                            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0});  // float64
}

TEST_CASE("a sequence of sequences: counts, elements, an empty inner sequence, then an aligned float64") {
  // As in int16[][] (a sequence of a message holding an int16[]): count 2; {count 1: -2}; {count 0}.
  CdrWriter cdr;
  cdr.u8(9);
  cdr.sequence_length(2);  // offset 1 -> 4
  cdr.sequence_length(1);  // offset 8
  cdr.i16(-2);             // offset 12
  cdr.sequence_length(0);  // offset 14 -> 16
  cdr.f64(0.5);            // offset 20 -> 24: 0x3FE0000000000000
  CHECK(cdr.data() == Bytes{0x00, 0x01, 0x00, 0x00,                           //
                            0x09, 0x00, 0x00, 0x00,                            // uint8, pad to 4
                            0x02, 0x00, 0x00, 0x00,                            // outer count
                            0x01, 0x00, 0x00, 0x00,                            // first inner count
                            0xFE, 0xFF,                                        // int16 -2
                            0x00, 0x00,                                        // pad to 16
                            0x00, 0x00, 0x00, 0x00,                            // second inner count
                            0x00, 0x00, 0x00, 0x00,                            // pad to 24
                            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0x3F});  // float64
}

TEST_CASE("signed values, a bool, a float32 and a uint64 take their two's complement and IEEE bytes") {
  CdrWriter cdr;
  cdr.boolean(true);
  cdr.i8(-1);
  cdr.f32(1.5F);      // offset 2 -> 4: 0x3FC00000
  cdr.i64(-2);        // offset 8
  cdr.i32(-3);        // offset 16
  cdr.u64(0x0102030405060708ULL);  // offset 20 -> 24
  CHECK(cdr.data() == Bytes{0x00, 0x01, 0x00, 0x00,                           //
                            0x01, 0xFF, 0x00, 0x00,                            // bool, int8, pad
                            0x00, 0x00, 0xC0, 0x3F,                            // float32
                            0xFE, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,    // int64
                            0xFD, 0xFF, 0xFF, 0xFF,                            // int32
                            0x00, 0x00, 0x00, 0x00,                            // pad to 24
                            0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01});  // uint64
}

TEST_CASE("arrays: raw bytes unaligned, float32 and float64 elements aligned once, no length") {
  CdrWriter cdr;
  const std::uint8_t raw[3] = {1, 2, 3};
  cdr.bytes(raw, 3);  // offsets 0..2, no padding
  const float floats[2] = {1.0F, -1.0F};
  cdr.f32_array(floats, 2);  // offset 3 -> 4
  const double doubles[1] = {2.0};
  cdr.f64_array(doubles, 1);  // offset 12 -> 16
  cdr.f64_array(nullptr, 0);  // nothing, not even padding
  cdr.u8(4);
  CHECK(cdr.data() == Bytes{0x00, 0x01, 0x00, 0x00,                           //
                            1, 2, 3, 0x00,                                     // bytes, pad to 4
                            0x00, 0x00, 0x80, 0x3F, 0x00, 0x00, 0x80, 0xBF,    // float32 x2
                            0x00, 0x00, 0x00, 0x00,                            // pad to 16
                            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40,    // float64
                            0x04});
}

TEST_CASE("a sequence longer than a uint32 can count is refused, and take() hands the bytes over") {
  CdrWriter cdr;
  if constexpr (sizeof(std::size_t) > 4) {
    const std::size_t too_long = std::size_t{std::numeric_limits<std::uint32_t>::max()} + 1;
    CHECK_THROWS_AS(cdr.sequence_length(too_long), std::length_error);
  }
  cdr.u8(5);
  const Bytes taken = cdr.take();
  CHECK(taken == Bytes{0x00, 0x01, 0x00, 0x00, 0x05});
}
