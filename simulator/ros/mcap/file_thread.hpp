// SPDX-License-Identifier: GPL-2.0-or-later
// FileThread: the thread that puts an MCAP file on disk, so that the simulation thread never waits for the
// disk or for zstd. It takes the header and Schema/Channel records (written as they come, in the data
// section) and closed chunks (compressed, CRC'd and written as one write together with their MessageIndex
// records, so that a process killed at any moment leaves every earlier chunk whole for a streaming reader);
// on finish it writes DataEnd, the summary (Schema, Channel, ChunkIndex and Statistics groups), the
// SummaryOffset records, the Footer and the closing magic, and syncs.
//
// Failures stop the bag, never the caller: after a write or sync error (a full disk) nothing more is written
// and the file ends where the disk stopped it (readable as a crashed one); when closed chunks waiting pass
// the queue's byte limit (a disk that fell behind) the chunk is dropped with all later ones, what was
// queued before is still written, and finish still writes a valid summary of what the file holds.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "ros/mcap/mcap_records.hpp"
#include "ros/mcap/open_chunk.hpp"

struct ZSTD_CCtx_s;

namespace rfbsim::ros::mcap {

/// How the thread writes.
struct FileThreadSettings {
  bool zstd = true;                           ///< compress chunks with zstd ("zstd"), else store them ("")
  int zstd_level = 3;                         ///< zstd's level (1 fast .. 19 small)
  bool sync = true;                           ///< fdatasync after each chunk
  std::size_t max_queued_bytes = 32u << 20;   ///< uncompressed chunk bytes waiting; more is a failure
  /// Bytes the file system must keep free after a chunk; a chunk that would leave less fails the bag (0 = no
  /// floor). The bag is the session's largest file and a copy of the others: it must not take their last space.
  std::uint64_t min_free_bytes = 0;
};

class FileThread {
 public:
  /// Takes over `fd` (open for writing, empty) of the file `path` and starts the thread; if that throws
  /// (no memory, no thread), `fd` is closed.
  FileThread(int fd, std::filesystem::path path, FileThreadSettings settings);
  /// finish().
  ~FileThread();
  FileThread(const FileThread&) = delete;
  FileThread& operator=(const FileThread&) = delete;

  /// Queues bytes for the data section as they are: the magic and Header (opcode kHeader), or one Schema or
  /// Channel record (kSchema, kChannel), which the summary repeats. Never refused by the byte limit.
  void write_record(Opcode kind, std::vector<std::uint8_t> bytes);
  /// Queues a closed chunk. False when the bag has failed or this chunk would pass the byte limit (which
  /// fails the bag): the chunk is dropped.
  bool write_chunk(ClosedChunk chunk);
  /// Waits until everything queued so far has been written (or dropped).
  void drain();
  /// Writes what is queued, then the summary and footer (unless a write failed), syncs the file and its
  /// folder, closes the file and stops the thread. Later calls do nothing.
  void finish();

  /// Why the bag stopped, on one line; none while all is well. Any thread.
  [[nodiscard]] std::optional<std::string> failure() const;
  /// Whether the bag has stopped (cheap; any thread).
  [[nodiscard]] bool failed() const { return failed_.load(std::memory_order_relaxed); }
  /// Bytes written to the file so far. Any thread.
  [[nodiscard]] std::uint64_t file_bytes() const { return file_bytes_.load(std::memory_order_relaxed); }

 private:
  struct Job {
    enum class Kind { kRecord, kChunk, kFinish } kind = Kind::kFinish;
    Opcode record_kind = Opcode::kHeader;
    std::vector<std::uint8_t> bytes;
    ClosedChunk chunk;
  };

  void run();
  void perform(Job& job);
  void write_chunk_now(ClosedChunk& chunk);
  void write_summary();
  bool write_bytes(const std::vector<std::uint8_t>& bytes, bool in_data_section);  // false: failed
  bool sync_file();
  void fail(const std::string& reason);  // the first failure is kept

  const std::filesystem::path path_;
  const FileThreadSettings settings_;

  // Writer thread only.
  int fd_ = -1;
  ZSTD_CCtx_s* zstd_ = nullptr;
  std::uint64_t offset_ = 0;     // bytes in the file
  std::uint32_t data_crc_ = 0;   // CRC-32 of the data section so far (from the leading magic on)
  bool write_failed_ = false;    // nothing more goes to the file
  bool folder_synced_ = false;   // the file's name is on disk
  std::vector<std::uint8_t> schemas_;   // the Schema records, for the summary
  std::vector<std::uint8_t> channels_;  // the Channel records, for the summary
  std::vector<ChunkIndex> chunk_indexes_;
  Statistics stats_;
  std::vector<std::uint8_t> compressed_;  // reused between chunks
  std::vector<std::uint8_t> out_;         // reused between chunks

  mutable std::mutex mutex_;
  std::condition_variable wake_;     // a job was queued
  std::condition_variable drained_;  // the queue emptied and the thread is idle
  bool busy_ = false;                // the thread is doing a job it took off the queue
  std::deque<Job> queue_;
  std::size_t queued_bytes_ = 0;  // chunk bytes queued or being written
  bool finishing_ = false;
  std::optional<std::string> failure_;
  std::atomic<bool> failed_{false};
  std::atomic<std::uint64_t> file_bytes_{0};
  std::thread thread_;
};

}  // namespace rfbsim::ros::mcap
