// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/mcap/mcap_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

#include "ros/mcap/file_thread.hpp"
#include "ros/mcap/mcap_records.hpp"
#include "ros/mcap/open_chunk.hpp"

namespace rfbsim::ros {

McapWriter::McapWriter(std::filesystem::path file, McapOptions options)
    : path_(std::move(file)), options_(std::move(options)), chunk_(std::make_unique<mcap::OpenChunk>()) {
  const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    throw std::runtime_error("cannot create the bag " + path_.string() + ": " + std::strerror(errno));
  }
  thread_ = std::make_unique<mcap::FileThread>(
      fd, path_,
      mcap::FileThreadSettings{options_.compression == McapOptions::Compression::kZstd, options_.zstd_level,
                               options_.sync, options_.max_queued_bytes, options_.min_free_bytes});
  std::vector<std::uint8_t> start(mcap::kMagic.begin(), mcap::kMagic.end());
  mcap::append_header(start, "ros2", options_.library);
  thread_->write_record(mcap::Opcode::kHeader, std::move(start));
}

McapWriter::~McapWriter() {
  try {
    finish();
  } catch (...) {  // a destructor must not throw; finish() reports through failure()
  }
}

std::uint16_t McapWriter::add_schema(std::string name, std::string encoding, std::string data) {
  if (finished_) throw std::logic_error("McapWriter::add_schema after finish()");
  if (schema_count_ == std::numeric_limits<std::uint16_t>::max()) {
    throw std::length_error("an MCAP file holds at most 65535 schemas");
  }
  const mcap::Schema schema{static_cast<std::uint16_t>(schema_count_ + 1), std::move(name), std::move(encoding),
                            std::move(data)};
  std::vector<std::uint8_t> record;
  mcap::append_schema(record, schema);
  thread_->write_record(mcap::Opcode::kSchema, std::move(record));
  return ++schema_count_;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, std::string topic, std::string message_encoding,
                                      std::map<std::string, std::string> metadata) {
  if (finished_) throw std::logic_error("McapWriter::add_channel after finish()");
  if (schema_id > schema_count_) {
    throw std::invalid_argument("McapWriter::add_channel: no schema " + std::to_string(schema_id) + " for " + topic);
  }
  if (sequences_.size() == std::numeric_limits<std::uint16_t>::max()) {
    throw std::length_error("an MCAP file holds at most 65535 channels");
  }
  const auto id = static_cast<std::uint16_t>(sequences_.size() + 1);
  std::vector<std::uint8_t> record;
  mcap::append_channel(record, mcap::Channel{id, schema_id, std::move(topic), std::move(message_encoding),
                                             std::move(metadata)});
  // Queued now, so that it reaches the data section before the chunk that is open (and may use it).
  thread_->write_record(mcap::Opcode::kChannel, std::move(record));
  sequences_.push_back(0);
  return id;
}

void McapWriter::write(std::uint16_t channel, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                       const std::uint8_t* data, std::size_t size) {
  if (channel == 0 || channel > sequences_.size()) {
    throw std::invalid_argument("McapWriter::write: no channel " + std::to_string(channel));
  }
  if (finished_ || thread_->failed()) return;
  if (chunk_->empty()) chunk_opened_ = std::chrono::steady_clock::now();
  chunk_->add(channel, sequences_[channel - 1u]++, log_time_ns, publish_time_ns, data, size);
  messages_.fetch_add(1, std::memory_order_relaxed);
  if (chunk_->bytes() >= options_.chunk_bytes) close_chunk();
}

void McapWriter::flush_if_due() {
  if (finished_ || chunk_->empty()) return;
  if (std::chrono::steady_clock::now() - chunk_opened_ >= options_.chunk_interval) close_chunk();
}

void McapWriter::close_chunk() {
  const std::uint64_t count = chunk_->message_count();
  // The next chunk keeps a full chunk's room ready (up to 4 MiB), so that write() does not reallocate as
  // it fills.
  const std::size_t reserve = std::min<std::size_t>(options_.chunk_bytes + options_.chunk_bytes / 8, 4u << 20);
  if (!thread_->write_chunk(chunk_->close(reserve))) messages_.fetch_sub(count, std::memory_order_relaxed);
}

void McapWriter::drain() { thread_->drain(); }

void McapWriter::finish() {
  if (finished_) return;
  finished_ = true;
  if (!chunk_->empty()) close_chunk();
  thread_->finish();
}

std::optional<std::string> McapWriter::failure() const { return thread_->failure(); }

std::uint64_t McapWriter::message_count() const { return messages_.load(std::memory_order_relaxed); }

std::uint64_t McapWriter::file_bytes() const { return thread_->file_bytes(); }

}  // namespace rfbsim::ros
