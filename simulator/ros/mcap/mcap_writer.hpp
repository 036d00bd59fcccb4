// SPDX-License-Identifier: GPL-2.0-or-later
// McapWriter: a ROS 2 bag (MCAP, profile "ros2") written while the session runs. The simulation thread adds
// schemas and channels and writes messages into the open chunk (a buffer append); a chunk closes when it
// holds chunk_bytes or, through flush_if_due(), when it has been open chunk_interval; a thread of the
// writer's own compresses and writes it with its MessageIndex records (file_thread.hpp). finish() writes the
// summary (Schema, Channel, ChunkIndex, Statistics, SummaryOffset), the footer and the closing magic.
//
// The file as written by https://mcap.dev/spec: Schema and Channel records go to the data section as they
// are added (before any chunk that uses them) and are repeated in the summary; every chunk carries the CRC of
// its uncompressed records, DataEnd the CRC of the data section, the Footer the CRC of the summary. A killed
// process leaves every chunk written before the kill readable by a streaming reader (the indexed reader
// needs the summary, so it refuses such a file); finish() or the destructor makes it whole.
//
// Threads: all members are for one thread (the simulation's), except failure(), message_count() and
// file_bytes(), which any thread may call. The caller never waits for the disk except in finish().
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::ros {

namespace mcap {
class FileThread;
class OpenChunk;
}  // namespace mcap

/// How the bag is chunked, compressed and synced.
struct McapOptions {
  std::size_t chunk_bytes = 256 * 1024;           ///< uncompressed bytes that close a chunk
  std::chrono::milliseconds chunk_interval{1000};  ///< an open chunk this old closes (a crash loses <= this)
  enum class Compression { kZstd, kNone } compression = Compression::kZstd;  ///< kZstd: "zstd" chunks
  int zstd_level = 3;                              ///< zstd's level (1 fast .. 19 small)
  bool sync = true;                                ///< fdatasync after each chunk (on the writer thread)
  std::string library = "rfbsim";                  ///< the Header's library field
  std::size_t max_queued_bytes = 32u << 20;        ///< closed chunks waiting for the disk; more fails the bag
  /// Free bytes a chunk must leave on the file system, or the bag stops (failure()) and the rest of the session's
  /// files keep the space: 64 MiB by default; 0 = no floor.
  std::uint64_t min_free_bytes = 64u << 20;
};

class McapWriter {
 public:
  /// Creates `file` (it must not exist: O_EXCL, mode 0600) and queues the magic and Header{profile "ros2"}.
  /// Throws std::runtime_error naming the path when the file cannot be created.
  McapWriter(std::filesystem::path file, McapOptions options = {});
  /// finish(); errors are left in failure().
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Adds a Schema (ids from 1): `name` e.g. "geometry_msgs/msg/Twist", `encoding` e.g. "ros2msg", `data` the
  /// definition. Throws std::length_error past 65535 schemas, std::logic_error after finish().
  std::uint16_t add_schema(std::string name, std::string encoding, std::string data);
  /// Adds a Channel (ids from 1) on `topic` for messages encoded as `message_encoding` (e.g. "cdr") with
  /// schema `schema_id` (0: none). Throws std::invalid_argument for an unknown schema id, std::length_error
  /// past 65535 channels, std::logic_error after finish().
  std::uint16_t add_channel(std::uint16_t schema_id, std::string topic, std::string message_encoding,
                            std::map<std::string, std::string> metadata = {});
  /// Appends a message on `channel` (sequence numbers per channel from 0) logged at `log_time_ns`; `data` may
  /// be null when `size` is 0. Throws std::invalid_argument for an unknown channel. Dropped silently after a
  /// failure or after finish().
  void write(std::uint16_t channel, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             const std::uint8_t* data, std::size_t size);
  /// Closes the open chunk if it has been open chunk_interval or longer; never waits for the disk.
  void flush_if_due();
  /// Waits until every chunk closed so far is in the file (not the open one); a checkpoint for tests.
  void drain();
  /// Closes the chunk, writes DataEnd, the summary, the footer and the magic, and waits until the file is
  /// on disk. Later calls do nothing.
  void finish();

  /// Why the bag stopped (a write error, a disk that fell behind), on one line; none while all is well.
  [[nodiscard]] std::optional<std::string> failure() const;
  /// Messages in the bag: written or on their way to the file (not those dropped after a failure).
  [[nodiscard]] std::uint64_t message_count() const;
  /// Bytes written to the file so far (after finish: its size).
  [[nodiscard]] std::uint64_t file_bytes() const;

 private:
  void close_chunk();

  const std::filesystem::path path_;
  const McapOptions options_;
  std::unique_ptr<mcap::OpenChunk> chunk_;
  std::chrono::steady_clock::time_point chunk_opened_;
  std::uint16_t schema_count_ = 0;
  std::vector<std::uint32_t> sequences_;  // per channel id - 1: the next sequence number
  std::atomic<std::uint64_t> messages_{0};  // in the open chunk or handed to the thread
  bool finished_ = false;
  std::unique_ptr<mcap::FileThread> thread_;
};

}  // namespace rfbsim::ros
