// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/mcap/open_chunk.hpp"

#include <algorithm>
#include <utility>

namespace rfbsim::ros::mcap {

void OpenChunk::add(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                    std::uint64_t publish_time, const std::uint8_t* data, std::size_t size) {
  indexes_[channel_id].push_back(IndexEntry{log_time, records_.size()});
  append_message(records_, channel_id, sequence, log_time, publish_time, data, size);
  // Min and max, not first and last: log times may go back (the spec asks for the earliest and latest).
  start_ = message_count_ == 0 ? log_time : std::min(start_, log_time);
  end_ = message_count_ == 0 ? log_time : std::max(end_, log_time);
  ++message_count_;
}

ClosedChunk OpenChunk::close(std::size_t reserve) {
  // Readers look messages up by time through the index: keep each channel's entries in time order even if
  // a caller logged out of order (stable, so equal times keep the order they were written in).
  for (auto& [channel, entries] : indexes_) {
    const auto by_time = [](const IndexEntry& a, const IndexEntry& b) { return a.log_time < b.log_time; };
    if (!std::is_sorted(entries.begin(), entries.end(), by_time)) {
      std::stable_sort(entries.begin(), entries.end(), by_time);
    }
  }
  ClosedChunk chunk{std::move(records_), start_, end_, std::move(indexes_), message_count_};
  records_ = {};
  records_.reserve(reserve);
  indexes_ = {};
  start_ = end_ = message_count_ = 0;
  return chunk;
}

}  // namespace rfbsim::ros::mcap
