// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/mcap/mcap_records.hpp"

#include <zlib.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "ros/mcap/little_endian.hpp"

namespace rfbsim::ros::mcap {

namespace {

std::uint32_t checked_u32(std::size_t n, const char* what) {
  if (n > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error(std::string("MCAP ") + what + " of " + std::to_string(n) + " bytes exceeds 4 GiB");
  }
  return static_cast<std::uint32_t>(n);
}

void put_bytes(std::vector<std::uint8_t>& out, const void* data, std::size_t size) {
  if (size == 0) return;
  const auto* p = static_cast<const std::uint8_t*>(data);
  out.insert(out.end(), p, p + size);
}

// Map and Array fields: a uint32 byte length written once the entries are in.
std::size_t begin_sized(std::vector<std::uint8_t>& out) {
  const std::size_t at = out.size();
  put_le(out, std::uint32_t{0});
  return at;
}

void end_sized(std::vector<std::uint8_t>& out, std::size_t at) {
  const std::uint32_t n = checked_u32(out.size() - at - 4, "map or array");
  for (std::size_t i = 0; i < 4; ++i) out[at + i] = static_cast<std::uint8_t>(n >> (8 * i));
}

void put_u16_u64_map(std::vector<std::uint8_t>& out, const std::map<std::uint16_t, std::uint64_t>& map) {
  const std::size_t at = begin_sized(out);
  for (const auto& [key, value] : map) {
    put_le(out, key);
    put_le(out, value);
  }
  end_sized(out, at);
}

}  // namespace

std::size_t begin_record(std::vector<std::uint8_t>& out, Opcode opcode) {
  out.push_back(static_cast<std::uint8_t>(opcode));
  const std::size_t at = out.size();
  put_le(out, std::uint64_t{0});
  return at;
}

void end_record(std::vector<std::uint8_t>& out, std::size_t length_at) {
  patch_le64(out, length_at, out.size() - length_at - 8);
}

void put_string(std::vector<std::uint8_t>& out, std::string_view s) {
  put_le(out, checked_u32(s.size(), "string"));
  put_bytes(out, s.data(), s.size());
}

void append_header(std::vector<std::uint8_t>& out, std::string_view profile, std::string_view library) {
  const std::size_t at = begin_record(out, Opcode::kHeader);
  put_string(out, profile);
  put_string(out, library);
  end_record(out, at);
}

void append_schema(std::vector<std::uint8_t>& out, const Schema& schema) {
  const std::size_t at = begin_record(out, Opcode::kSchema);
  put_le(out, schema.id);
  put_string(out, schema.name);
  put_string(out, schema.encoding);
  put_string(out, schema.data);  // data is uint32 length-prefixed Bytes: the same layout as a String
  end_record(out, at);
}

void append_channel(std::vector<std::uint8_t>& out, const Channel& channel) {
  const std::size_t at = begin_record(out, Opcode::kChannel);
  put_le(out, channel.id);
  put_le(out, channel.schema_id);
  put_string(out, channel.topic);
  put_string(out, channel.message_encoding);
  const std::size_t map_at = begin_sized(out);
  for (const auto& [key, value] : channel.metadata) {
    put_string(out, key);
    put_string(out, value);
  }
  end_sized(out, map_at);
  end_record(out, at);
}

void append_message(std::vector<std::uint8_t>& out, std::uint16_t channel_id, std::uint32_t sequence,
                    std::uint64_t log_time, std::uint64_t publish_time, const std::uint8_t* data, std::size_t size) {
  // The length is known up front: no patching, one growth of the buffer.
  out.reserve(out.size() + kRecordPrefixBytes + kMessageFieldsBytes + size);
  out.push_back(static_cast<std::uint8_t>(Opcode::kMessage));
  put_le(out, std::uint64_t{kMessageFieldsBytes + size});
  put_le(out, channel_id);
  put_le(out, sequence);
  put_le(out, log_time);
  put_le(out, publish_time);
  put_bytes(out, data, size);
}

void append_chunk(std::vector<std::uint8_t>& out, std::uint64_t message_start_time, std::uint64_t message_end_time,
                  std::uint64_t uncompressed_size, std::uint32_t uncompressed_crc, std::string_view compression,
                  const std::uint8_t* records, std::size_t records_size) {
  out.reserve(out.size() + kRecordPrefixBytes + 8 + 8 + 8 + 4 + 4 + compression.size() + 8 + records_size);
  const std::size_t at = begin_record(out, Opcode::kChunk);
  put_le(out, message_start_time);
  put_le(out, message_end_time);
  put_le(out, uncompressed_size);
  put_le(out, uncompressed_crc);
  put_string(out, compression);
  put_le(out, std::uint64_t{records_size});  // records: uint64 length-prefixed Bytes
  put_bytes(out, records, records_size);
  end_record(out, at);
}

void append_message_index(std::vector<std::uint8_t>& out, std::uint16_t channel_id,
                          const std::vector<IndexEntry>& entries) {
  const std::size_t at = begin_record(out, Opcode::kMessageIndex);
  put_le(out, channel_id);
  const std::size_t array_at = begin_sized(out);
  for (const IndexEntry& entry : entries) {
    put_le(out, entry.log_time);
    put_le(out, entry.offset);
  }
  end_sized(out, array_at);
  end_record(out, at);
}

void append_chunk_index(std::vector<std::uint8_t>& out, const ChunkIndex& index) {
  const std::size_t at = begin_record(out, Opcode::kChunkIndex);
  put_le(out, index.message_start_time);
  put_le(out, index.message_end_time);
  put_le(out, index.chunk_start_offset);
  put_le(out, index.chunk_length);
  put_u16_u64_map(out, index.message_index_offsets);
  put_le(out, index.message_index_length);
  put_string(out, index.compression);
  put_le(out, index.compressed_size);
  put_le(out, index.uncompressed_size);
  end_record(out, at);
}

void append_statistics(std::vector<std::uint8_t>& out, const Statistics& stats) {
  const std::size_t at = begin_record(out, Opcode::kStatistics);
  put_le(out, stats.message_count);
  put_le(out, stats.schema_count);
  put_le(out, stats.channel_count);
  put_le(out, std::uint32_t{0});  // attachment_count
  put_le(out, std::uint32_t{0});  // metadata_count
  put_le(out, stats.chunk_count);
  put_le(out, stats.message_start_time);
  put_le(out, stats.message_end_time);
  put_u16_u64_map(out, stats.channel_message_counts);
  end_record(out, at);
}

void append_summary_offset(std::vector<std::uint8_t>& out, Opcode group_opcode, std::uint64_t group_start,
                           std::uint64_t group_length) {
  const std::size_t at = begin_record(out, Opcode::kSummaryOffset);
  out.push_back(static_cast<std::uint8_t>(group_opcode));
  put_le(out, group_start);
  put_le(out, group_length);
  end_record(out, at);
}

void append_data_end(std::vector<std::uint8_t>& out, std::uint32_t data_section_crc) {
  const std::size_t at = begin_record(out, Opcode::kDataEnd);
  put_le(out, data_section_crc);
  end_record(out, at);
}

void append_footer_prefix(std::vector<std::uint8_t>& out, std::uint64_t summary_start,
                          std::uint64_t summary_offset_start) {
  out.push_back(static_cast<std::uint8_t>(Opcode::kFooter));
  put_le(out, std::uint64_t{8 + 8 + 4});  // the Footer's fixed length, summary_crc included
  put_le(out, summary_start);
  put_le(out, summary_offset_start);
}

std::uint32_t crc32_update(std::uint32_t crc, const std::uint8_t* data, std::size_t size) {
  // zlib's crc32 takes a uInt length: feed it in pieces so that any size_t works.
  uLong value = crc;
  while (size > 0) {
    const std::size_t piece = std::min<std::size_t>(size, 1u << 30);
    value = ::crc32(value, data, static_cast<uInt>(piece));
    data += piece;
    size -= piece;
  }
  return static_cast<std::uint32_t>(value);
}

}  // namespace rfbsim::ros::mcap
