// SPDX-License-Identifier: GPL-2.0-or-later
#include "mcap_walker.hpp"

#include <zlib.h>
#include <zstd.h>

#include <fstream>
#include <iterator>
#include <stdexcept>

namespace rfbsim::test::mcap {

namespace {

std::uint64_t le(const std::uint8_t* p, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v |= std::uint64_t{p[i]} << (8 * i);
  return v;
}

}  // namespace

Bytes Fields::bytes(std::size_t n) {
  if (n > remaining()) throw std::out_of_range("MCAP field past the end of its record");
  Bytes out(bytes_.begin() + static_cast<std::ptrdiff_t>(at_), bytes_.begin() + static_cast<std::ptrdiff_t>(at_ + n));
  at_ += n;
  return out;
}

std::uint8_t Fields::u8() { return bytes(1)[0]; }
std::uint16_t Fields::u16() { return static_cast<std::uint16_t>(le(bytes(2).data(), 2)); }
std::uint32_t Fields::u32() { return static_cast<std::uint32_t>(le(bytes(4).data(), 4)); }
std::uint64_t Fields::u64() { return le(bytes(8).data(), 8); }

std::string Fields::string() {
  const Bytes text = bytes(u32());
  return {text.begin(), text.end()};
}

Bytes read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<Record> walk(const Bytes& bytes, std::size_t begin, std::size_t end, bool& torn) {
  std::vector<Record> records;
  torn = false;
  std::size_t at = begin;
  while (at < end) {
    if (end - at < 9) {
      torn = true;
      break;
    }
    const std::uint64_t length = le(&bytes[at + 1], 8);
    if (length > end - at - 9) {
      torn = true;
      break;
    }
    const auto from = bytes.begin() + static_cast<std::ptrdiff_t>(at + 9);
    records.push_back(Record{bytes[at], at, Bytes(from, from + static_cast<std::ptrdiff_t>(length))});
    at += 9 + length;
  }
  return records;
}

std::uint32_t crc_of(const Bytes& bytes, std::size_t begin, std::size_t end) {
  return static_cast<std::uint32_t>(::crc32_z(0, bytes.data() + begin, end - begin));
}

Chunk open_chunk(const Record& record) {
  if (record.opcode != 0x06) throw std::runtime_error("not a Chunk record");
  Fields f(record.content);
  Chunk chunk;
  chunk.start = f.u64();
  chunk.end = f.u64();
  chunk.uncompressed_size = f.u64();
  chunk.crc = f.u32();
  chunk.compression = f.string();
  chunk.stored_size = f.u64();
  const Bytes stored = f.bytes(chunk.stored_size);
  if (f.remaining() != 0) throw std::runtime_error("bytes after a Chunk's records");
  if (chunk.compression == "zstd") {
    chunk.records.resize(chunk.uncompressed_size);
    const std::size_t n = ZSTD_decompress(chunk.records.data(), chunk.records.size(), stored.data(), stored.size());
    if (ZSTD_isError(n) != 0 || n != chunk.uncompressed_size) throw std::runtime_error("bad zstd chunk");
  } else if (chunk.compression.empty()) {
    chunk.records = stored;
  } else {
    throw std::runtime_error("unknown compression " + chunk.compression);
  }
  if (chunk.records.size() != chunk.uncompressed_size) throw std::runtime_error("chunk size mismatch");
  if (crc_of(chunk.records, 0, chunk.records.size()) != chunk.crc) throw std::runtime_error("chunk CRC mismatch");
  return chunk;
}

}  // namespace rfbsim::test::mcap
