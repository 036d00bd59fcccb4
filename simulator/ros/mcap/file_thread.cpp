// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/mcap/file_thread.hpp"

#include <sys/statvfs.h>

#include <fcntl.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <new>
#include <utility>

#include "ros/mcap/little_endian.hpp"

namespace rfbsim::ros::mcap {

namespace {

std::string errno_text(int error) { return std::strerror(error); }

}  // namespace

FileThread::FileThread(int fd, std::filesystem::path path, FileThreadSettings settings)
    : path_(std::move(path)), settings_(settings), fd_(fd) {
  try {
    if (settings_.zstd && (zstd_ = ZSTD_createCCtx()) == nullptr) throw std::bad_alloc();
    thread_ = std::thread([this] { run(); });
  } catch (...) {
    // The file is ours from the first line: close it rather than leak it with the half-built object.
    ZSTD_freeCCtx(zstd_);
    ::close(fd_);
    throw;
  }
}

FileThread::~FileThread() { finish(); }

void FileThread::write_record(Opcode kind, std::vector<std::uint8_t> bytes) {
  const std::lock_guard lock(mutex_);
  if (finishing_) return;
  Job job;
  job.kind = Job::Kind::kRecord;
  job.record_kind = kind;
  job.bytes = std::move(bytes);
  queue_.push_back(std::move(job));
  wake_.notify_one();
}

bool FileThread::write_chunk(ClosedChunk chunk) {
  const std::lock_guard lock(mutex_);
  if (finishing_ || failure_) return false;
  const std::size_t size = chunk.records.size();
  if (queued_bytes_ + size > settings_.max_queued_bytes) {
    // The disk is this far behind the simulation: stop the bag rather than grow without bound.
    failure_ = path_.filename().string() + ": the disk fell behind (" + std::to_string(queued_bytes_ + size) +
               " bytes waiting, limit " + std::to_string(settings_.max_queued_bytes) +
               "); messages from log time " + std::to_string(chunk.message_start_time) + " ns on are dropped";
    failed_.store(true, std::memory_order_relaxed);
    return false;
  }
  queued_bytes_ += size;
  Job job;
  job.kind = Job::Kind::kChunk;
  job.chunk = std::move(chunk);
  queue_.push_back(std::move(job));
  wake_.notify_one();
  return true;
}

void FileThread::finish() {
  {
    const std::lock_guard lock(mutex_);
    if (finishing_) return;
    finishing_ = true;
    queue_.push_back(Job{});  // kFinish
    wake_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
}

void FileThread::drain() {
  std::unique_lock lock(mutex_);
  drained_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

std::optional<std::string> FileThread::failure() const {
  const std::lock_guard lock(mutex_);
  return failure_;
}

void FileThread::fail(const std::string& reason) {
  const std::lock_guard lock(mutex_);
  if (!failure_) failure_ = reason;
  failed_.store(true, std::memory_order_relaxed);
}

void FileThread::run() {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return !queue_.empty(); });
      job = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    const bool last = job.kind == Job::Kind::kFinish;
    const std::size_t chunk_bytes = job.kind == Job::Kind::kChunk ? job.chunk.records.size() : 0;
    perform(job);
    {
      // The chunk's memory counts against the limit until it is written, not only while it waits.
      const std::lock_guard lock(mutex_);
      queued_bytes_ -= chunk_bytes;
      busy_ = false;
      if (queue_.empty()) drained_.notify_all();
    }
    if (last) return;
  }
}

void FileThread::perform(Job& job) {
  switch (job.kind) {
    case Job::Kind::kRecord:
      if (job.record_kind == Opcode::kSchema) {
        schemas_.insert(schemas_.end(), job.bytes.begin(), job.bytes.end());
        ++stats_.schema_count;
      } else if (job.record_kind == Opcode::kChannel) {
        channels_.insert(channels_.end(), job.bytes.begin(), job.bytes.end());
        ++stats_.channel_count;
      }
      write_bytes(job.bytes, true);
      return;
    case Job::Kind::kChunk:
      write_chunk_now(job.chunk);
      return;
    case Job::Kind::kFinish:
      if (!write_failed_) write_summary();
      if (!write_failed_) sync_file();
      if (zstd_ != nullptr) ZSTD_freeCCtx(zstd_);
      zstd_ = nullptr;
      if (fd_ >= 0 && ::close(fd_) != 0 && !write_failed_) {
        fail(path_.filename().string() + ": close failed (" + errno_text(errno) + ")");
      }
      fd_ = -1;
      return;
  }
}

void FileThread::write_chunk_now(ClosedChunk& chunk) {
  if (write_failed_) return;
  if (settings_.min_free_bytes > 0) {
    struct statvfs disk {};
    const std::uint64_t needed = settings_.min_free_bytes + chunk.records.size();
    if (::fstatvfs(fd_, &disk) == 0 && static_cast<std::uint64_t>(disk.f_bavail) * disk.f_frsize < needed) {
      fail(path_.filename().string() + ": stopped at byte " + std::to_string(offset_) + ": the disk has less than " +
           std::to_string(settings_.min_free_bytes >> 20) + " MiB free, which the session's other files keep");
      return;
    }
  }
  const std::uint32_t crc = crc32_update(0, chunk.records.data(), chunk.records.size());

  // Compress (or store) the records.
  const std::uint8_t* stored = chunk.records.data();
  std::size_t stored_size = chunk.records.size();
  const char* compression = "";
  if (zstd_ != nullptr) {
    compressed_.resize(ZSTD_compressBound(chunk.records.size()));
    const std::size_t n = ZSTD_compressCCtx(zstd_, compressed_.data(), compressed_.size(), chunk.records.data(),
                                            chunk.records.size(), settings_.zstd_level);
    if (ZSTD_isError(n) != 0) {
      write_failed_ = true;
      fail(path_.filename().string() + ": zstd failed (" + ZSTD_getErrorName(n) + ")");
      return;
    }
    stored = compressed_.data();
    stored_size = n;
    compression = "zstd";
  }

  // The Chunk record and its MessageIndex records, as one write: a kill leaves all of it or a torn tail.
  out_.clear();
  ChunkIndex index;
  index.message_start_time = chunk.message_start_time;
  index.message_end_time = chunk.message_end_time;
  index.chunk_start_offset = offset_;
  append_chunk(out_, chunk.message_start_time, chunk.message_end_time, chunk.records.size(), crc, compression,
               stored, stored_size);
  index.chunk_length = out_.size();
  for (const auto& [channel, entries] : chunk.indexes) {
    index.message_index_offsets[channel] = offset_ + out_.size();
    append_message_index(out_, channel, entries);
  }
  index.message_index_length = out_.size() - index.chunk_length;
  index.compression = compression;
  index.compressed_size = stored_size;
  index.uncompressed_size = chunk.records.size();
  if (!write_bytes(out_, true)) return;

  // Only what reached the file counts in the summary.
  if (stats_.chunk_count == 0 && stats_.message_count == 0) {
    stats_.message_start_time = chunk.message_start_time;
    stats_.message_end_time = chunk.message_end_time;
  } else {
    stats_.message_start_time = std::min(stats_.message_start_time, chunk.message_start_time);
    stats_.message_end_time = std::max(stats_.message_end_time, chunk.message_end_time);
  }
  ++stats_.chunk_count;
  stats_.message_count += chunk.message_count;
  for (const auto& [channel, entries] : chunk.indexes) stats_.channel_message_counts[channel] += entries.size();
  chunk_indexes_.push_back(std::move(index));
  if (settings_.sync) sync_file();
}

void FileThread::write_summary() {
  out_.clear();
  append_data_end(out_, data_crc_);
  if (!write_bytes(out_, false)) return;

  // The summary, grouped by opcode, each group's place noted for its SummaryOffset record.
  const std::uint64_t summary_start = offset_;
  std::vector<std::uint8_t> summary;
  struct Group {
    Opcode opcode;
    std::uint64_t start;
    std::uint64_t length;
  };
  std::vector<Group> groups;
  const auto group = [&](Opcode opcode, const auto& append) {
    const std::size_t begin = summary.size();
    append();
    if (summary.size() > begin) groups.push_back({opcode, summary_start + begin, summary.size() - begin});
  };
  group(Opcode::kSchema, [&] { summary.insert(summary.end(), schemas_.begin(), schemas_.end()); });
  group(Opcode::kChannel, [&] { summary.insert(summary.end(), channels_.begin(), channels_.end()); });
  group(Opcode::kChunkIndex, [&] {
    for (const ChunkIndex& index : chunk_indexes_) append_chunk_index(summary, index);
  });
  // Statistics after the Channel group, as the spec asks when channel_message_counts is filled.
  group(Opcode::kStatistics, [&] { append_statistics(summary, stats_); });

  const std::uint64_t summary_offset_start = summary_start + summary.size();
  for (const Group& g : groups) append_summary_offset(summary, g.opcode, g.start, g.length);

  // The footer's CRC covers the summary, the summary offsets and the footer up to the CRC itself.
  append_footer_prefix(summary, summary_start, summary_offset_start);
  put_le(summary, crc32_update(0, summary.data(), summary.size()));
  summary.insert(summary.end(), kMagic.begin(), kMagic.end());
  write_bytes(summary, false);
}

bool FileThread::write_bytes(const std::vector<std::uint8_t>& bytes, bool in_data_section) {
  if (write_failed_) return false;
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : ENOSPC;
      offset_ += done;
      file_bytes_.store(offset_, std::memory_order_relaxed);
      write_failed_ = true;
      fail(path_.filename().string() + ": write failed at byte " + std::to_string(offset_) + " (" +
           errno_text(error) + "); the bag ends at its last whole chunk");
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  // The data section's CRC starts at the file's first byte, as the reference writers compute it.
  if (in_data_section) data_crc_ = crc32_update(data_crc_, bytes.data(), bytes.size());
  offset_ += bytes.size();
  file_bytes_.store(offset_, std::memory_order_relaxed);
  return true;
}

bool FileThread::sync_file() {
  if (::fdatasync(fd_) != 0) {
    write_failed_ = true;
    fail(path_.filename().string() + ": fdatasync failed (" + errno_text(errno) + ")");
    return false;
  }
  if (!folder_synced_) {
    // Once, so that the file's name survives a power cut, not only its blocks.
    folder_synced_ = true;
    const std::filesystem::path folder = path_.parent_path().empty() ? "." : path_.parent_path();
    const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {
      ::fsync(dir);
      ::close(dir);
    }
  }
  return true;
}

}  // namespace rfbsim::ros::mcap
