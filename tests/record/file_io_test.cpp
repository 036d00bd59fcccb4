// SPDX-License-Identifier: GPL-2.0-or-later
// The file steps under session data: failures come back as one line naming the file, never thrown.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include "record/file_io.hpp"
#include "scratch_dir.hpp"

using namespace rfbsim::sim;
using rfbsim::test::ScratchDir;

TEST_CASE("a write to a full device says so, naming the file, with nothing written") {
  UniqueFd full(::open("/dev/full", O_WRONLY | O_CLOEXEC));
  REQUIRE(full.valid());
  const FileResult result = write_all(full.get(), "tick\n", "events.jsonl");
  CHECK(result.error == "events.jsonl: cannot write (No space left on device)");
  CHECK(result.written == 0);
}

TEST_CASE("replace_file puts the whole new text in place, owner-only, and leaves no temporary behind") {
  ScratchDir scratch;
  std::string error;
  UniqueFd dir = open_dir(scratch.path(), error);
  REQUIRE(dir.valid());
  REQUIRE(replace_file(scratch.path(), dir.get(), "doc.json", "{\"a\":1}\n").ok());
  REQUIRE(replace_file(scratch.path(), dir.get(), "doc.json", "{\"a\":2}\n").ok());
  CHECK(scratch.read("doc.json") == "{\"a\":2}\n");
  CHECK_FALSE(std::filesystem::exists(scratch.path() / "doc.json.tmp"));
  struct stat info {};
  REQUIRE(::stat((scratch.path() / "doc.json").c_str(), &info) == 0);
  CHECK((info.st_mode & 0777) == 0600);

  // A folder that is gone: an error in words, the old document untouched elsewhere.
  const FileResult missing = replace_file(scratch.path() / "gone", dir.get(), "doc.json", "x");
  CHECK_THAT(missing.error, Catch::StartsWith("doc.json.tmp: cannot open for writing (No such file or directory)"));
}

TEST_CASE("reserve_space sets the bytes aside in a file of that size") {
  ScratchDir scratch;
  const auto path = scratch.path() / "room.reserve";
  REQUIRE(reserve_space(path, 16384).ok());
  CHECK(std::filesystem::file_size(path) == 16384);
  CHECK_FALSE(reserve_space(scratch.path() / "gone" / "room.reserve", 4096).ok());
}

TEST_CASE("one_line keeps a reason on one short line") {
  CHECK(one_line("a\nb\r\tc") == "a b  c");
  CHECK(one_line(std::string(500, 'x')).size() == 200);
  CHECK(one_line("short", 3) == "sho");
}
