// SPDX-License-Identifier: GPL-2.0-or-later
// OpenChunk: the chunk the simulation thread is filling. A message is appended as a whole Message record to
// the uncompressed records, with a MessageIndex entry (log time, offset) for its channel; closing hands the
// lot over as a ClosedChunk for the writer thread to compress and write. Appending is a buffer append and a
// vector push: no compression, no system call.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "ros/mcap/mcap_records.hpp"

namespace rfbsim::ros::mcap {

/// A finished chunk's content, still uncompressed.
struct ClosedChunk {
  std::vector<std::uint8_t> records;                            ///< Message records, back to back
  std::uint64_t message_start_time = 0;                         ///< ns, min log time
  std::uint64_t message_end_time = 0;                           ///< ns, max log time
  std::map<std::uint16_t, std::vector<IndexEntry>> indexes;     ///< channel -> entries by log time
  std::uint64_t message_count = 0;
};

class OpenChunk {
 public:
  /// Appends one message; `data` may be null when `size` is 0.
  void add(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time, std::uint64_t publish_time,
           const std::uint8_t* data, std::size_t size);
  /// Whether no message has been added since the last close.
  [[nodiscard]] bool empty() const { return message_count_ == 0; }
  /// Uncompressed bytes so far.
  [[nodiscard]] std::size_t bytes() const { return records_.size(); }
  /// Messages so far.
  [[nodiscard]] std::uint64_t message_count() const { return message_count_; }
  /// Hands the content over (indexes sorted by log time) and starts an empty chunk that keeps `reserve`
  /// bytes ready, so that the next chunk's appends do not reallocate.
  ClosedChunk close(std::size_t reserve);

 private:
  std::vector<std::uint8_t> records_;
  std::map<std::uint16_t, std::vector<IndexEntry>> indexes_;
  std::uint64_t start_ = 0;
  std::uint64_t end_ = 0;
  std::uint64_t message_count_ = 0;
};

}  // namespace rfbsim::ros::mcap
