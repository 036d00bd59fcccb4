// SPDX-License-Identifier: GPL-2.0-or-later
// Test helper: a small, independent MCAP reader for the writer's tests. It walks a file's records by opcode
// and length, reads fields little-endian, and opens chunks (zstd or stored) checking their CRC, so that the
// tests can assert the layout the specification asks for without trusting the writer's own code.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace rfbsim::test::mcap {

using Bytes = std::vector<std::uint8_t>;

/// One record: its opcode, the file (or chunk) offset of its opcode, and its content.
struct Record {
  std::uint8_t opcode = 0;
  std::uint64_t offset = 0;
  Bytes content;
};

/// Little-endian fields of a record's content, in order; throws std::out_of_range past the end.
class Fields {
 public:
  explicit Fields(const Bytes& bytes) : bytes_(bytes) {}
  std::uint8_t u8();
  std::uint16_t u16();
  std::uint32_t u32();
  std::uint64_t u64();
  std::string string();   ///< uint32 length, bytes
  Bytes bytes(std::size_t n);
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - at_; }

 private:
  const Bytes& bytes_;
  std::size_t at_ = 0;
};

/// The whole file.
Bytes read_file(const std::filesystem::path& path);

/// Records back to back from `begin` to `end` of `bytes`; a record that does not fit sets `torn` and stops.
std::vector<Record> walk(const Bytes& bytes, std::size_t begin, std::size_t end, bool& torn);

/// A Chunk record's fields, its records decompressed; throws std::runtime_error when the size or CRC is wrong.
struct Chunk {
  std::uint64_t start = 0, end = 0, uncompressed_size = 0;
  std::uint32_t crc = 0;
  std::string compression;
  std::uint64_t stored_size = 0;
  Bytes records;
};
Chunk open_chunk(const Record& record);

/// The CRC-32 of bytes [begin, end) of `bytes`, with zlib.
std::uint32_t crc_of(const Bytes& bytes, std::size_t begin, std::size_t end);

}  // namespace rfbsim::test::mcap
