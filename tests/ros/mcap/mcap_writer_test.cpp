// SPDX-License-Identifier: GPL-2.0-or-later
// McapWriter's files walked record by record (mcap_walker.hpp) against the specification: magic, Header
// (ros2), Schema and Channel records before the chunks that use them, each chunk's CRC, times and
// MessageIndex records, DataEnd with the data section's CRC, the summary grouped by opcode with its
// SummaryOffset records, Statistics, and the Footer with the summary's CRC; then a writer killed after some
// chunks (every one readable), a chunk closed by its age, and a disk that fell behind (a valid, shorter bag).
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "mcap_walker.hpp"
#include "ros/mcap/mcap_writer.hpp"
#include "scratch_dir.hpp"

using namespace rfbsim::test::mcap;
using rfbsim::ros::McapOptions;
using rfbsim::ros::McapWriter;
using rfbsim::test::ScratchDir;

namespace {

const Bytes kMagicBytes = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

// What a bag holds, as read back.
struct Contents {
  std::size_t schemas = 0, channels = 0, chunks = 0;
  std::map<std::uint16_t, std::uint64_t> per_channel;  // messages
  std::uint64_t messages = 0, start = 0, end = 0;
  std::vector<Bytes> chunk_index_contents;  // expected ChunkIndex record contents, in file order
  std::vector<Bytes> schema_records, channel_records;
};

// Appends little-endian bytes (to build the expected ChunkIndex contents independently of the writer).
void le(Bytes& out, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

// Walks the data section [8, end): checks every chunk and its indexes, returns what it holds. `torn` says
// whether the walk stopped at a record that does not fit.
Contents check_data_section(const Bytes& file, std::size_t end, bool& torn, bool expect_data_end) {
  REQUIRE(file.size() >= 8);
  REQUIRE(Bytes(file.begin(), file.begin() + 8) == kMagicBytes);
  const std::vector<Record> records = walk(file, 8, end, torn);
  REQUIRE(!records.empty());
  REQUIRE(records[0].opcode == 0x01);  // Header
  Fields header(records[0].content);
  CHECK(header.string() == "ros2");
  CHECK(header.string() == "rfbsim-test");

  Contents c;
  std::set<std::uint16_t> schemas{0}, channels;
  std::map<std::uint16_t, std::uint32_t> next_sequence;
  bool first_message = true;
  for (std::size_t i = 1; i < records.size(); ++i) {
    const Record& r = records[i];
    if (r.opcode == 0x03) {  // Schema
      Fields f(r.content);
      schemas.insert(f.u16());
      c.schema_records.push_back(r.content);
      ++c.schemas;
    } else if (r.opcode == 0x04) {  // Channel, whose schema came earlier
      Fields f(r.content);
      channels.insert(f.u16());
      CHECK(schemas.count(f.u16()) == 1);
      c.channel_records.push_back(r.content);
      ++c.channels;
    } else if (r.opcode == 0x06) {  // Chunk: open it (size and CRC checked), then its message indexes
      const Chunk chunk = open_chunk(r);
      ++c.chunks;
      bool inner_torn = false;
      const std::vector<Record> messages = walk(chunk.records, 0, chunk.records.size(), inner_torn);
      REQUIRE_FALSE(inner_torn);
      std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> expected_index;
      std::uint64_t lo = ~0ULL, hi = 0;
      for (const Record& m : messages) {
        REQUIRE(m.opcode == 0x05);
        Fields f(m.content);
        const std::uint16_t channel = f.u16();
        CHECK(channels.count(channel) == 1);  // its Channel record came first
        CHECK(f.u32() == next_sequence[channel]++);
        const std::uint64_t log_time = f.u64();
        CHECK(f.u64() == log_time + 1);  // the tests publish 1 ns after logging
        expected_index[channel].emplace_back(log_time, m.offset);
        lo = std::min(lo, log_time);
        hi = std::max(hi, log_time);
        ++c.per_channel[channel];
        ++c.messages;
        c.start = first_message ? log_time : std::min(c.start, log_time);
        c.end = first_message ? log_time : std::max(c.end, log_time);
        first_message = false;
      }
      CHECK(chunk.start == lo);
      CHECK(chunk.end == hi);
      // One MessageIndex per channel in the chunk, right after it, pointing at its messages.
      Bytes index_offsets;
      const std::uint64_t index_start = i + 1 < records.size() ? records[i + 1].offset : 0;
      for (std::size_t k = 0; k < expected_index.size(); ++k) {
        REQUIRE(i + 1 < records.size());
        const Record& mi = records[++i];
        REQUIRE(mi.opcode == 0x07);
        Fields f(mi.content);
        const std::uint16_t channel = f.u16();
        REQUIRE(expected_index.count(channel) == 1);
        const auto& entries = expected_index[channel];
        REQUIRE(f.u32() == entries.size() * 16);
        for (const auto& [time, offset] : entries) {
          CHECK(f.u64() == time);
          CHECK(f.u64() == offset);
        }
        CHECK(f.remaining() == 0);
        le(index_offsets, channel, 2);
        le(index_offsets, mi.offset, 8);
      }
      const std::uint64_t index_end = i + 1 < records.size() ? records[i + 1].offset : end;
      Bytes ci;
      le(ci, chunk.start, 8);
      le(ci, chunk.end, 8);
      le(ci, r.offset, 8);
      le(ci, 9 + r.content.size(), 8);
      le(ci, index_offsets.size(), 4);
      ci.insert(ci.end(), index_offsets.begin(), index_offsets.end());
      le(ci, index_end - index_start, 8);
      le(ci, chunk.compression.size(), 4);
      ci.insert(ci.end(), chunk.compression.begin(), chunk.compression.end());
      le(ci, chunk.stored_size, 8);
      le(ci, chunk.uncompressed_size, 8);
      c.chunk_index_contents.push_back(ci);
    } else if (r.opcode == 0x0F) {  // DataEnd: last, with the CRC of everything before it
      CHECK(i == records.size() - 1);
      Fields f(r.content);
      CHECK(f.u32() == crc_of(file, 0, r.offset));
    } else {
      FAIL("unexpected opcode " << int{r.opcode} << " in the data section at " << r.offset);
    }
  }
  CHECK((records.back().opcode == 0x0F) == expect_data_end);
  return c;
}

// Checks a finished bag from its footer back and returns what it holds.
Contents check_finished(const Bytes& file) {
  REQUIRE(file.size() >= 8 + 29 + 8);
  REQUIRE(Bytes(file.end() - 8, file.end()) == kMagicBytes);
  const std::size_t footer_at = file.size() - 8 - 29;
  bool torn = false;
  const std::vector<Record> footer_records = walk(file, footer_at, file.size() - 8, torn);
  REQUIRE(footer_records.size() == 1);
  REQUIRE(footer_records[0].opcode == 0x02);
  Fields footer(footer_records[0].content);
  const std::uint64_t summary_start = footer.u64();
  const std::uint64_t summary_offset_start = footer.u64();
  CHECK(footer.u32() == crc_of(file, summary_start, footer_at + 9 + 16));

  Contents c = check_data_section(file, summary_start, torn, true);
  CHECK_FALSE(torn);

  // The summary: groups of one opcode each, exactly as the SummaryOffset records list them.
  const std::vector<Record> summary = walk(file, summary_start, summary_offset_start, torn);
  CHECK_FALSE(torn);
  const std::vector<Record> offsets = walk(file, summary_offset_start, footer_at, torn);
  CHECK_FALSE(torn);
  std::map<std::uint8_t, std::vector<const Record*>> groups;
  std::uint8_t last = 0;
  for (const Record& r : summary) {
    if (r.opcode != last) CHECK(groups.count(r.opcode) == 0);  // grouped: each opcode in one run
    groups[r.opcode].push_back(&r);
    last = r.opcode;
  }
  REQUIRE(offsets.size() == groups.size());
  for (const Record& o : offsets) {
    REQUIRE(o.opcode == 0x0E);
    Fields f(o.content);
    const std::uint8_t opcode = f.u8();
    REQUIRE(groups.count(opcode) == 1);
    const auto& group = groups[opcode];
    CHECK(f.u64() == group.front()->offset);
    CHECK(f.u64() == group.back()->offset + 9 + group.back()->content.size() - group.front()->offset);
  }

  // Schema and Channel records repeated; one ChunkIndex per chunk; Statistics after the channels.
  std::vector<Bytes> schemas, channels, chunk_indexes;
  for (const Record* r : groups[0x03]) schemas.push_back(r->content);
  for (const Record* r : groups[0x04]) channels.push_back(r->content);
  for (const Record* r : groups[0x08]) chunk_indexes.push_back(r->content);
  CHECK(schemas == c.schema_records);
  CHECK(channels == c.channel_records);
  CHECK(chunk_indexes == c.chunk_index_contents);
  REQUIRE(groups[0x0B].size() == 1);
  if (!groups[0x04].empty()) CHECK(groups[0x04].back()->offset < groups[0x0B].front()->offset);
  Fields stats(groups[0x0B].front()->content);
  CHECK(stats.u64() == c.messages);
  CHECK(stats.u16() == c.schemas);
  CHECK(stats.u32() == c.channels);
  CHECK(stats.u32() == 0);  // attachments
  CHECK(stats.u32() == 0);  // metadata
  CHECK(stats.u32() == c.chunks);
  CHECK(stats.u64() == c.start);
  CHECK(stats.u64() == c.end);
  REQUIRE(stats.u32() == c.per_channel.size() * 10);
  for (const auto& [channel, count] : c.per_channel) {
    CHECK(stats.u16() == channel);
    CHECK(stats.u64() == count);
  }
  CHECK(stats.remaining() == 0);
  return c;
}

// Two schemas, three channels (one without a schema, one with metadata).
struct Channels {
  std::uint16_t a = 0, b = 0, c = 0;
};
Channels add_channels(McapWriter& bag) {
  const std::uint16_t string_schema = bag.add_schema("std_msgs/msg/String", "ros2msg", "string data\n");
  const std::uint16_t twist_schema = bag.add_schema("geometry_msgs/msg/Twist", "ros2msg", "float64 x\n");
  CHECK(string_schema == 1);
  CHECK(twist_schema == 2);
  Channels ids;
  ids.a = bag.add_channel(string_schema, "/events", "cdr");
  ids.b = bag.add_channel(twist_schema, "/cmd_vel", "cdr", {{"offered_qos_profiles", "- durability: 2\n"}});
  ids.c = bag.add_channel(0, "/raw", "x-raw");
  return ids;
}

void write_messages(McapWriter& bag, const Channels& ids, int count, std::uint64_t t0) {
  for (int i = 0; i < count; ++i) {
    const std::uint16_t channel = i % 3 == 0 ? ids.a : i % 3 == 1 ? ids.b : ids.c;
    const std::vector<std::uint8_t> data(static_cast<std::size_t>(5 + i % 17), static_cast<std::uint8_t>(i));
    const std::uint64_t t = t0 + static_cast<std::uint64_t>(i / 2) * 1000;  // times repeat in pairs
    bag.write(channel, t, t + 1, data.data(), data.size());
  }
}

}  // namespace

TEST_CASE("a finished bag has every record, index and CRC the specification asks for") {
  const auto compression = GENERATE(McapOptions::Compression::kZstd, McapOptions::Compression::kNone);
  ScratchDir dir("rfbsim_mcap");
  McapOptions options;
  options.chunk_bytes = 1000;
  options.compression = compression;
  options.sync = false;
  options.library = "rfbsim-test";
  McapWriter bag(dir.path() / "session.mcap", options);
  const Channels ids = add_channels(bag);
  CHECK(ids.a == 1);
  write_messages(bag, ids, 300, 5'000'000'000);
  bag.finish();
  bag.finish();  // idempotent

  const Bytes file = read_file(dir.path() / "session.mcap");
  const Contents c = check_finished(file);
  CHECK(c.messages == 300);
  CHECK(c.schemas == 2);
  CHECK(c.channels == 3);
  CHECK(c.chunks > 5);
  CHECK(c.per_channel == std::map<std::uint16_t, std::uint64_t>{{1, 100}, {2, 100}, {3, 100}});
  CHECK(c.start == 5'000'000'000);
  CHECK(c.end == 5'000'000'000 + 149 * 1000);
  CHECK(bag.message_count() == 300);
  CHECK(bag.file_bytes() == file.size());
  CHECK_FALSE(bag.failure());
}

TEST_CASE("an empty bag is still a whole file with a summary") {
  ScratchDir dir("rfbsim_mcap");
  McapOptions options;
  options.library = "rfbsim-test";
  { McapWriter bag(dir.path() / "empty.mcap", options); }  // the destructor finishes it
  const Contents c = check_finished(read_file(dir.path() / "empty.mcap"));
  CHECK(c.messages == 0);
  CHECK(c.chunks == 0);
}

TEST_CASE("a chunk closes by age only when flush_if_due finds it due") {
  ScratchDir dir("rfbsim_mcap");
  McapOptions options;
  options.library = "rfbsim-test";
  options.sync = false;
  options.chunk_interval = std::chrono::hours(1);
  McapWriter bag(dir.path() / "session.mcap", options);
  const Channels ids = add_channels(bag);
  write_messages(bag, ids, 3, 1000);
  bag.flush_if_due();  // an hour has not passed: the chunk stays open
  bag.drain();
  bool torn = false;
  Bytes file = read_file(dir.path() / "session.mcap");
  CHECK(check_data_section(file, file.size(), torn, false).chunks == 0);
  bag.finish();
  CHECK(check_finished(read_file(dir.path() / "session.mcap")).chunks == 1);

  // With no interval, every flush_if_due closes the open chunk.
  options.chunk_interval = std::chrono::milliseconds(0);
  McapWriter eager(dir.path() / "eager.mcap", options);
  const Channels eager_ids = add_channels(eager);
  for (int k = 0; k < 4; ++k) {
    write_messages(eager, eager_ids, 3, 1000 + static_cast<std::uint64_t>(k) * 100'000);
    eager.flush_if_due();
  }
  eager.flush_if_due();  // nothing open: no empty chunk
  eager.finish();
  CHECK(check_finished(read_file(dir.path() / "eager.mcap")).chunks == 4);
}

TEST_CASE("a writer killed by SIGKILL leaves every chunk it wrote readable, and no summary") {
  ScratchDir dir("rfbsim_mcap");
  const std::filesystem::path path = dir.path() / "killed.mcap";
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    // The child writes three chunks, leaves a fourth open, waits for the disk and dies without finishing.
    McapOptions options;
    options.library = "rfbsim-test";
    options.chunk_interval = std::chrono::milliseconds(0);
    McapWriter bag(path, options);
    const Channels ids = add_channels(bag);
    for (int k = 0; k < 3; ++k) {
      write_messages(bag, ids, 30, static_cast<std::uint64_t>(k) * 100'000);
      bag.flush_if_due();
    }
    write_messages(bag, ids, 7, 1'000'000);
    bag.drain();
    ::raise(SIGKILL);
    ::_exit(1);
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  REQUIRE(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGKILL);

  const Bytes file = read_file(path);
  bool torn = false;
  const Contents c = check_data_section(file, file.size(), torn, false);
  CHECK_FALSE(torn);
  CHECK(c.chunks == 3);
  CHECK(c.messages == 90);
}

TEST_CASE("a disk that falls behind fails the bag, drops the rest, and finish still writes a valid file") {
  ScratchDir dir("rfbsim_mcap");
  McapOptions options;
  options.library = "rfbsim-test";
  options.chunk_bytes = 500;
  options.max_queued_bytes = 1;  // no chunk fits: the first one overflows, as behind a stalled disk
  McapWriter bag(dir.path() / "session.mcap", options);
  const Channels ids = add_channels(bag);
  write_messages(bag, ids, 100, 0);
  REQUIRE(bag.failure());
  CHECK(bag.failure()->find("session.mcap: the disk fell behind") == 0);
  CHECK(bag.message_count() == 0);
  bag.finish();
  const Contents c = check_finished(read_file(dir.path() / "session.mcap"));
  CHECK(c.messages == 0);
  CHECK(c.channels == 3);
}
