// SPDX-License-Identifier: GPL-2.0-or-later
// McapWriter when things go wrong: a file that exists or a folder that does not (a clear error naming the
// path), a disk that fills while the bag is written (a real file size limit: the bag reports it in
// failure(), the caller goes on, and the file holds whole chunks up to where the disk stopped), and ids that
// were never handed out (refused).
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stdexcept>
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

// The message of what `make` throws, "" if it does not.
template <typename F>
std::string error_of(F make) {
  try {
    make();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// What a child that writes a bag of 200 messages to `path` under a 4 KiB file size limit reports: its wait
// status and its text (the bag's failure, then "wrote all 200" once its loop and finish() returned).
struct FullDiskRun {
  int status = 0;
  std::string report;
};

FullDiskRun write_bag_until_disk_full(const std::string& path) {
  int pipe_fds[2];
  REQUIRE(::pipe(pipe_fds) == 0);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    // A 4 KiB file size limit stands for the full disk (writes past it fail with EFBIG); the child sends
    // back the failure and how many messages it got through, then exits normally.
    ::close(pipe_fds[0]);
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    McapOptions options;
    options.chunk_bytes = 600;
    options.compression = McapOptions::Compression::kNone;
    options.sync = false;
    std::string report;
    {
      McapWriter bag(path, options);
      const std::uint16_t schema = bag.add_schema("std_msgs/msg/String", "ros2msg", "string data\n");
      const std::uint16_t channel = bag.add_channel(schema, "/events", "cdr");
      const std::vector<std::uint8_t> data(100, 7);
      for (std::uint64_t i = 0; i < 200; ++i) bag.write(channel, i, i, data.data(), data.size());
      bag.finish();
      report = bag.failure().value_or("no failure");
    }
    report += "\nwrote all 200";
    const auto written = ::write(pipe_fds[1], report.data(), report.size());
    ::_exit(written == static_cast<ssize_t>(report.size()) ? 0 : 1);
  }
  ::close(pipe_fds[1]);
  std::string report;
  char buffer[512];
  for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;) report.append(buffer, static_cast<std::size_t>(n));
  ::close(pipe_fds[0]);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  return {status, report};
}

}  // namespace

TEST_CASE("a bag is never written over an existing file, nor into a missing folder") {
  ScratchDir dir("rfbsim_mcap");
  const std::string existing = dir.write("session.mcap", "earlier data");
  const std::string exists_error = error_of([&] { McapWriter bag(existing); });
  CHECK(exists_error.find(existing) != std::string::npos);
  CHECK(exists_error.find("File exists") != std::string::npos);
  CHECK(dir.read("session.mcap") == "earlier data");

  const std::string missing = dir.path("no/such/folder/session.mcap");
  const std::string missing_error = error_of([&] { McapWriter bag(missing); });
  CHECK(missing_error.find(missing) != std::string::npos);
  CHECK(missing_error.find("No such file or directory") != std::string::npos);
}

TEST_CASE("a disk that fills stops the bag with a clear failure") {
  ScratchDir dir("rfbsim_mcap");
  const FullDiskRun run = write_bag_until_disk_full(dir.path("session.mcap"));
  INFO(run.report);
  CHECK(run.report.find("session.mcap: write failed at byte ") == 0);
  CHECK(run.report.find("File too large") != std::string::npos);
}

TEST_CASE("when the disk fills under a bag, the caller goes on") {
  ScratchDir dir("rfbsim_mcap");
  const FullDiskRun run = write_bag_until_disk_full(dir.path("session.mcap"));
  INFO(run.report);
  REQUIRE(WIFEXITED(run.status));
  CHECK(WEXITSTATUS(run.status) == 0);
  CHECK(run.report.find("wrote all 200") != std::string::npos);
}

TEST_CASE("when the disk fills under a bag, the whole chunks written before stay readable") {
  ScratchDir dir("rfbsim_mcap");
  const std::string path = dir.path("session.mcap");
  const FullDiskRun run = write_bag_until_disk_full(path);
  INFO(run.report);
  REQUIRE(WIFEXITED(run.status));

  // The file is cut at the limit: every whole chunk in it opens with a good CRC, and the tail is torn.
  const Bytes file = read_file(path);
  CHECK(file.size() == 4096);
  bool torn = false;
  const std::vector<Record> records = walk(file, 8, file.size(), torn);
  CHECK(torn);
  std::size_t chunks = 0;
  for (const Record& r : records) {
    if (r.opcode == 0x06) {
      CHECK_NOTHROW(open_chunk(r));
      ++chunks;
    }
    CHECK(r.opcode != 0x0F);  // no DataEnd: the summary never came
  }
  CHECK(chunks >= 4);
}

TEST_CASE("ids that were never handed out are refused") {
  ScratchDir dir("rfbsim_mcap");
  McapWriter bag(dir.path() / "session.mcap");
  CHECK_THROWS_AS(bag.add_channel(1, "/t", "cdr"), std::invalid_argument);  // no schema 1 yet
  const std::uint8_t byte = 0;
  CHECK_THROWS_AS(bag.write(1, 0, 0, &byte, 1), std::invalid_argument);  // no channel 1 yet
  const std::uint16_t schema = bag.add_schema("std_msgs/msg/String", "ros2msg", "string data\n");
  const std::uint16_t channel = bag.add_channel(schema, "/t", "cdr");
  CHECK_THROWS_AS(bag.write(0, 0, 0, &byte, 1), std::invalid_argument);
  CHECK_THROWS_AS(bag.write(static_cast<std::uint16_t>(channel + 1), 0, 0, &byte, 1), std::invalid_argument);
  bag.write(channel, 0, 0, nullptr, 0);  // an empty message is fine
  bag.finish();
  CHECK(bag.message_count() == 1);
  CHECK_FALSE(bag.failure());
  CHECK_THROWS_AS(bag.add_schema("a", "b", "c"), std::logic_error);
}

TEST_CASE("a bag stops at a chunk that would leave less than its free-space floor, and the file stays whole") {
  ScratchDir dir("rfbsim_mcap");
  McapOptions options;
  // No disk has this much free: the first chunk is refused, as on a nearly full one with the 64 MiB default.
  options.min_free_bytes = std::uint64_t{1} << 60;
  McapWriter bag(dir.path() / "session.mcap", options);
  const std::uint16_t schema = bag.add_schema("std_msgs/msg/String", "ros2msg", "string data\n");
  const std::uint16_t channel = bag.add_channel(schema, "/t", "cdr");
  const std::vector<std::uint8_t> message(100, 7);
  bag.write(channel, 1, 1, message.data(), message.size());
  bag.finish();
  REQUIRE(bag.failure());
  CHECK(bag.failure()->find("MiB free, which the session's other files keep") != std::string::npos);
  // What was written before it (magic, header) is still a readable start of a file, with no chunk.
  const Bytes bytes = read_file(dir.path() / "session.mcap");
  bool torn = false;
  const std::vector<Record> records = walk(bytes, 8, bytes.size(), torn);
  for (const Record& record : records) CHECK(record.opcode != 0x06);
}
