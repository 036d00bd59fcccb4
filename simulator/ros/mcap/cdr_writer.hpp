// SPDX-License-Identifier: GPL-2.0-or-later
// CdrWriter: one ROS 2 message in CDR, the encoding of the `cdr` message encoding in MCAP's ros2 profile and of
// rosbag2. It is classic CDR (XCDR1), little-endian: a 4-byte encapsulation header 00 01 00 00 (CDR_LE), then
// the fields in definition order, each primitive aligned to its own size counted from the byte after the
// header (so a float64 after a uint8 skips 7 bytes). Strings are a uint32 length that counts the NUL, the
// bytes and the NUL; sequences a uint32 element count and the elements; fixed arrays the elements alone.
//
// The caller writes the fields of its message type in order (msgs/ does that per type); the writer knows
// nothing of types, it only lays the bytes out. It owns its buffer; take() hands the buffer over.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace rfbsim::ros {

class CdrWriter {
 public:
  /// Starts a message: the buffer holds the encapsulation header 00 01 00 00.
  CdrWriter();

  /// A bool as one byte, 0 or 1.
  void boolean(bool v);
  /// A uint8 (also ROS's byte and char).
  void u8(std::uint8_t v);
  /// An int8.
  void i8(std::int8_t v);
  /// A uint16, 2-aligned.
  void u16(std::uint16_t v);
  /// An int16, 2-aligned.
  void i16(std::int16_t v);
  /// A uint32, 4-aligned.
  void u32(std::uint32_t v);
  /// An int32, 4-aligned.
  void i32(std::int32_t v);
  /// A uint64, 8-aligned.
  void u64(std::uint64_t v);
  /// An int64, 8-aligned.
  void i64(std::int64_t v);
  /// A float32 (IEEE 754), 4-aligned.
  void f32(float v);
  /// A float64 (IEEE 754), 8-aligned.
  void f64(double v);
  /// A string: 4-aligned uint32 length counting the NUL, the bytes, a NUL. Throws std::length_error when
  /// the length does not fit a uint32.
  void string(std::string_view s);
  /// A sequence's element count as a 4-aligned uint32; the caller then writes the `n` elements. Throws
  /// std::length_error when `n` does not fit a uint32.
  void sequence_length(std::size_t n);
  /// `n` raw bytes, no alignment and no length: the contents of a uint8[] or int8[] (after its length, if a
  /// sequence). `data` may be null when `n` is 0.
  void bytes(const void* data, std::size_t n);
  /// `n` float32 values, the first 4-aligned, no length (a fixed array, or a sequence after its length).
  void f32_array(const float* v, std::size_t n);
  /// `n` float64 values, the first 8-aligned, no length.
  void f64_array(const double* v, std::size_t n);

  /// The message so far, header included.
  [[nodiscard]] const std::vector<std::uint8_t>& data() const { return buffer_; }
  /// Hands the message over; the writer is left empty (not even a header) and must not be used again.
  std::vector<std::uint8_t> take() { return std::move(buffer_); }

 private:
  void align(std::size_t n);  // zero padding up to a multiple of n, counted after the header

  std::vector<std::uint8_t> buffer_;
};

}  // namespace rfbsim::ros
