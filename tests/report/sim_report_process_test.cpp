// SPDX-License-Identifier: GPL-2.0-or-later
// The real sim_report binary on a generated data folder: its exit status, the files it writes, sessions.csv
// parsing to the right rows, manager.json's warnings and left-out sessions on stderr, what --log-level keeps of
// them, and the usage errors.
#include <catch2/catch.hpp>

#include <string>

#include "session_files.hpp"
#include "sim_report_runner.hpp"

using namespace rfbsim::report::test;

TEST_CASE("sim_report writes the four files for a data folder and sessions.csv has a row per session") {
  ScratchDir scratch;
  const auto data = scratch.path() / "data";
  for (const char* uid : {"p001", "p002", "p003"}) {
    SessionSpec spec = small_session();
    spec.uid = uid;
    write_session(data / "sessions" / (std::string("1-") + uid), spec);
  }

  CHECK(sim_report(scratch, quoted(data)) == 0);
  for (const char* name : {"sessions.csv", "summary.csv", "report.md", "report.html"}) {
    INFO(name);
    CHECK(std::filesystem::is_regular_file(data / "report" / name));
  }
  const auto rows = csv_records(read_text(data / "report" / "sessions.csv"));
  REQUIRE(rows.size() == 3);
  CHECK(rows[0].at("uid") == "p001");
  CHECK(rows[2].at("uid") == "p003");
  CHECK(rows[1].at("robot_path_length") == "0");
  CHECK_THAT(read_text(scratch.path() / "stdout.txt"), Catch::Contains("report.html"));
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"), Catch::Contains("3 sessions reported, 0 skipped"));
}

TEST_CASE("sim_report exits 1 and names a skipped session, writing the report of the others") {
  ScratchDir scratch;
  const auto data = scratch.path() / "data";
  write_session(data / "1-good", small_session());
  write_session(data / "2-bad", small_session());
  std::filesystem::remove(data / "2-bad" / "events.jsonl");

  CHECK(sim_report(scratch, quoted(data) + " --out " + quoted(scratch.path() / "out")) == 1);
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"),
             Catch::Contains("skipped 2-bad: ") && Catch::Contains("events.jsonl: missing"));
  CHECK(csv_records(read_text(scratch.path() / "out" / "sessions.csv")).size() == 1);
}

TEST_CASE("sim_report warns of a broken manager.json and says how many sessions had no participant") {
  ScratchDir scratch;
  const auto data = scratch.path() / "data";
  write_session(data / "1-seen", small_session());
  write_text(data / "1-seen" / "manager.json", manager_json("p001", "finished", 900));
  write_session(data / "2-unseen", small_session());
  write_text(data / "2-unseen" / "manager.json", manager_json("p001", "abandoned"));
  write_session(data / "3-broken", small_session());
  write_text(data / "3-broken" / "manager.json", "{\"uid\": \"p001\", \"state\": \"lost\"}");

  CHECK(sim_report(scratch, quoted(data)) == 0);
  const std::string err = read_text(scratch.path() / "stderr.txt");
  CHECK_THAT(err, Catch::Contains("[sim_report] warning: " + (data / "3-broken" / "manager.json").string() +
                                  ": key 'state': unknown state 'lost'; reported without it\n"));
  CHECK_THAT(err, Catch::Contains("3 sessions reported, 0 skipped\n"));
  CHECK_THAT(err, Catch::Contains("[sim_report] 1 of them without a participant (link never spent), left out of "
                                  "the statistics\n"));
  CHECK(csv_records(read_text(data / "report" / "summary.csv"))[0].at("sessions") == "2");
}

TEST_CASE("sim_report --log-level warn keeps the warnings and drops the counts, error drops both") {
  ScratchDir scratch;
  const auto data = scratch.path() / "data";
  write_session(data / "1-broken", small_session());
  write_text(data / "1-broken" / "manager.json", "{\"uid\": \"p001\", \"state\": \"lost\"}");

  CHECK(sim_report(scratch, quoted(data) + " --log-level warn") == 0);
  std::string err = read_text(scratch.path() / "stderr.txt");
  CHECK_THAT(err, Catch::Contains("[sim_report] warning: " + (data / "1-broken" / "manager.json").string()));
  CHECK_THAT(err, !Catch::Contains("sessions reported"));
  CHECK(sim_report(scratch, quoted(data) + " --log-level error") == 0);
  CHECK(read_text(scratch.path() / "stderr.txt").empty());
  CHECK(sim_report(scratch, quoted(data) + " --log-level debug") == 0);
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"), Catch::Contains("1 sessions reported, 0 skipped\n"));

  CHECK(sim_report(scratch, quoted(data) + " --log-level loud") == 2);
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"),
             Catch::Contains("bad value 'loud' for --log-level (expected error, warn, info or debug)"));
}

TEST_CASE("sim_report exits 2 on usage errors and 0 for help") {
  ScratchDir scratch;
  CHECK(sim_report(scratch, "") == 2);
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"), Catch::Contains("DATA_DIR is missing"));
  CHECK(sim_report(scratch, "--frobnicate " + quoted(scratch.path())) == 2);
  CHECK(sim_report(scratch, quoted(scratch.path() / "no-such-folder")) == 2);
  CHECK(sim_report(scratch, "--help") == 0);
  CHECK_THAT(read_text(scratch.path() / "stdout.txt"), Catch::Contains("usage: sim_report [OPTIONS] [DATA_DIR...]"));
}
