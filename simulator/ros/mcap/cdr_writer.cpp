// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/mcap/cdr_writer.hpp"

#include <bit>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "ros/mcap/little_endian.hpp"

namespace rfbsim::ros {

namespace {

// Alignment counts from the first byte after the encapsulation header (classic CDR, as ROS 2's Fast-CDR
// writes it with the CDR_LE header): the header is not part of the aligned stream.
constexpr std::size_t kHeaderBytes = 4;

std::uint32_t checked_u32(std::size_t n, const char* what) {
  if (n > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error(std::string("CDR ") + what + " of " + std::to_string(n) + " does not fit a uint32");
  }
  return static_cast<std::uint32_t>(n);
}

}  // namespace

CdrWriter::CdrWriter() : buffer_{0x00, 0x01, 0x00, 0x00} { buffer_.reserve(64); }

void CdrWriter::align(std::size_t n) {
  const std::size_t offset = buffer_.size() - kHeaderBytes;
  buffer_.resize(buffer_.size() + (n - offset % n) % n, 0);
}

void CdrWriter::boolean(bool v) { buffer_.push_back(v ? 1 : 0); }
void CdrWriter::u8(std::uint8_t v) { buffer_.push_back(v); }
void CdrWriter::i8(std::int8_t v) { buffer_.push_back(static_cast<std::uint8_t>(v)); }

void CdrWriter::u16(std::uint16_t v) {
  align(2);
  put_le(buffer_, v);
}
void CdrWriter::i16(std::int16_t v) { u16(static_cast<std::uint16_t>(v)); }

void CdrWriter::u32(std::uint32_t v) {
  align(4);
  put_le(buffer_, v);
}
void CdrWriter::i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }

void CdrWriter::u64(std::uint64_t v) {
  align(8);
  put_le(buffer_, v);
}
void CdrWriter::i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }

void CdrWriter::f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
void CdrWriter::f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }

void CdrWriter::string(std::string_view s) {
  u32(checked_u32(s.size() + 1, "string length"));
  bytes(s.data(), s.size());
  buffer_.push_back(0);
}

void CdrWriter::sequence_length(std::size_t n) { u32(checked_u32(n, "sequence length")); }

void CdrWriter::bytes(const void* data, std::size_t n) {
  if (n == 0) return;
  const auto* p = static_cast<const std::uint8_t*>(data);
  buffer_.insert(buffer_.end(), p, p + n);
}

void CdrWriter::f32_array(const float* v, std::size_t n) {
  if (n == 0) return;
  align(4);
  buffer_.reserve(buffer_.size() + 4 * n);
  for (std::size_t i = 0; i < n; ++i) put_le(buffer_, std::bit_cast<std::uint32_t>(v[i]));
}

void CdrWriter::f64_array(const double* v, std::size_t n) {
  if (n == 0) return;
  align(8);
  buffer_.reserve(buffer_.size() + 8 * n);
  for (std::size_t i = 0; i < n; ++i) put_le(buffer_, std::bit_cast<std::uint64_t>(v[i]));
}

}  // namespace rfbsim::ros
