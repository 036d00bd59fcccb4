// SPDX-License-Identifier: GPL-2.0-or-later
// The MCAP records rfbsim writes, laid out byte by byte as the MCAP specification (https://mcap.dev/spec,
// major version 0) defines them: every record is <opcode uint8><content length uint64><content>; integers
// are little-endian; a String is a uint32 byte length and the bytes; a Map or Array a uint32 byte length
// and the entries. Pure functions appending to a buffer: no files, no threads (the writer does those).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace rfbsim::ros::mcap {

/// The bytes an MCAP file starts and ends with: 0x89 "MCAP" '0' (the major version) "\r\n".
inline constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

/// Record opcodes (spec, "Records").
enum class Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// Bytes before a record's content: the opcode and the uint64 content length.
inline constexpr std::size_t kRecordPrefixBytes = 1 + 8;
/// Bytes of a Message record before its data: channel_id, sequence, log_time, publish_time.
inline constexpr std::size_t kMessageFieldsBytes = 2 + 4 + 8 + 8;

/// A Schema record: how a channel's messages are encoded (for ros2: a ros2msg definition).
struct Schema {
  std::uint16_t id = 0;  ///< from 1; 0 means "no schema" and is never written
  std::string name;      ///< the type, e.g. "geometry_msgs/msg/Twist"
  std::string encoding;  ///< e.g. "ros2msg"
  std::string data;      ///< the definition text
};

/// A Channel record: one topic and its encoding.
struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;                  ///< 0: no schema
  std::string topic;                            ///< e.g. "/cmd_vel"
  std::string message_encoding;                 ///< e.g. "cdr"
  std::map<std::string, std::string> metadata;  ///< e.g. offered_qos_profiles for rosbag2
};

/// One MessageIndex entry: a message's log time and its offset in the chunk's uncompressed records.
struct IndexEntry {
  std::uint64_t log_time = 0;  ///< ns
  std::uint64_t offset = 0;    ///< bytes from the start of the uncompressed records
};

/// A ChunkIndex record: where one chunk and its message indexes lie in the file.
struct ChunkIndex {
  std::uint64_t message_start_time = 0;  ///< ns, earliest log time in the chunk
  std::uint64_t message_end_time = 0;    ///< ns, latest log time in the chunk
  std::uint64_t chunk_start_offset = 0;  ///< file offset of the Chunk record's opcode
  std::uint64_t chunk_length = 0;        ///< the whole Chunk record, opcode and length included
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;  ///< channel -> file offset of its index
  std::uint64_t message_index_length = 0;  ///< all MessageIndex records after the chunk, in bytes
  std::string compression;                 ///< "zstd" or "" (none)
  std::uint64_t compressed_size = 0;       ///< the Chunk's records field as stored
  std::uint64_t uncompressed_size = 0;     ///< the records field uncompressed
};

/// A Statistics record: counts over the whole file.
struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;  ///< ns; 0 when there are no messages
  std::uint64_t message_end_time = 0;    ///< ns; 0 when there are no messages
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

/// Starts a record with `opcode` and a length to be patched: returns where the length field is.
std::size_t begin_record(std::vector<std::uint8_t>& out, Opcode opcode);
/// Patches the length of the record begun with `length_at` to cover everything appended since.
void end_record(std::vector<std::uint8_t>& out, std::size_t length_at);

/// Appends a String: uint32 byte length, the bytes. Throws std::length_error above 4 GiB.
void put_string(std::vector<std::uint8_t>& out, std::string_view s);

/// Appends a Header record (profile "ros2" for ROS 2 bags; library names the writer).
void append_header(std::vector<std::uint8_t>& out, std::string_view profile, std::string_view library);
/// Appends a Schema record.
void append_schema(std::vector<std::uint8_t>& out, const Schema& schema);
/// Appends a Channel record.
void append_channel(std::vector<std::uint8_t>& out, const Channel& channel);
/// Appends a Message record holding `size` bytes of `data` (may be null when `size` is 0).
void append_message(std::vector<std::uint8_t>& out, std::uint16_t channel_id, std::uint32_t sequence,
                    std::uint64_t log_time, std::uint64_t publish_time, const std::uint8_t* data, std::size_t size);
/// Appends a Chunk record around `records` (already compressed as `compression` says).
void append_chunk(std::vector<std::uint8_t>& out, std::uint64_t message_start_time, std::uint64_t message_end_time,
                  std::uint64_t uncompressed_size, std::uint32_t uncompressed_crc, std::string_view compression,
                  const std::uint8_t* records, std::size_t records_size);
/// Appends a MessageIndex record for one channel of a chunk.
void append_message_index(std::vector<std::uint8_t>& out, std::uint16_t channel_id,
                          const std::vector<IndexEntry>& entries);
/// Appends a ChunkIndex record.
void append_chunk_index(std::vector<std::uint8_t>& out, const ChunkIndex& index);
/// Appends a Statistics record (no attachments or metadata records: their counts are 0).
void append_statistics(std::vector<std::uint8_t>& out, const Statistics& stats);
/// Appends a SummaryOffset record: the group of summary records with `group_opcode` lies at
/// [`group_start`, `group_start` + `group_length`) in the file.
void append_summary_offset(std::vector<std::uint8_t>& out, Opcode group_opcode, std::uint64_t group_start,
                           std::uint64_t group_length);
/// Appends a DataEnd record.
void append_data_end(std::vector<std::uint8_t>& out, std::uint32_t data_section_crc);
/// Appends a Footer record without its summary_crc: the CRC covers the footer's bytes up to that field, so
/// the caller computes it over the summary and these bytes, then appends it with put_le.
void append_footer_prefix(std::vector<std::uint8_t>& out, std::uint64_t summary_start,
                          std::uint64_t summary_offset_start);

/// CRC-32 (the zlib/ISO-HDLC polynomial, as MCAP uses) of `size` bytes, continued from `crc` (0 to start).
std::uint32_t crc32_update(std::uint32_t crc, const std::uint8_t* data, std::size_t size);

}  // namespace rfbsim::ros::mcap
