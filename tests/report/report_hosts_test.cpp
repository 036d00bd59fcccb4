// SPDX-License-Identifier: GPL-2.0-or-later
// One dataset from many hosts: sim_report over several hosts' data folders and the shared store. Each
// session's host (manager.json's, else the store folder's), a uid on two hosts flagged in every format with
// the exit status unchanged, the same session found twice reported once, and the real binary on two folders.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "manager_record.hpp"
#include "report_job.hpp"
#include "session_catalog.hpp"
#include "session_files.hpp"
#include "sim_report_runner.hpp"

using namespace rfbsim::report;
using namespace rfbsim::report::test;

namespace {

// A small session of `uid` in `dir`, with a manager.json naming `host` (none: a manager.json without a host,
// as managers before issue 18 wrote it).
void host_session(const std::filesystem::path& dir, const std::string& uid, const std::optional<std::string>& host) {
  SessionSpec spec = small_session();
  spec.uid = uid;
  write_session(dir, spec);
  nlohmann::json record = nlohmann::json::parse(manager_json(uid, "finished", 900));
  if (host) record["host"] = *host;
  write_text(dir / "manager.json", record.dump() + "\n");
}

const std::map<std::string, std::string>& row_with(const std::vector<std::map<std::string, std::string>>& rows,
                                                   const std::string& folder_end) {
  const auto it = std::find_if(rows.begin(), rows.end(), [&](const auto& r) {
    const std::string& f = r.at("folder");
    return f.size() >= folder_end.size() && f.compare(f.size() - folder_end.size(), folder_end.size(), folder_end) == 0;
  });
  REQUIRE(it != rows.end());
  return *it;
}

}  // namespace

TEST_CASE("a uid with sessions on two hosts is flagged in every format, and the exit status stays 0") {
  ScratchDir scratch;
  const auto h1 = scratch.path() / "host-a", h2 = scratch.path() / "host-b";
  host_session(h1 / "sessions" / "1-p001", "p001", "h1");
  host_session(h1 / "sessions" / "2-p002", "p002", "h1");
  host_session(h2 / "sessions" / "1-p001", "p001", "h2");  // the same uid, and even the same folder name
  host_session(h2 / "sessions" / "2-p003", "p003", "h2");
  host_session(h2 / "sessions" / "3-p003", "p003", "h2");  // twice on one host: not a duplicate across hosts

  const auto out = scratch.path() / "out";
  const JobResult result = run_report({h1, h2}, out);
  CHECK(result.exit_status() == 0);
  CHECK(result.sessions_reported == 5);
  CHECK(result.repeats.empty());
  REQUIRE(result.duplicate_uids.size() == 1);
  CHECK(result.duplicate_uids[0] == "uid 'p001' has sessions on 2 hosts: h1 (" +
                                        (h1 / "sessions" / "1-p001").string() + "), h2 (" +
                                        (h2 / "sessions" / "1-p001").string() + ")");

  const auto rows = csv_records(read_text(out / "sessions.csv"));
  REQUIRE(rows.size() == 5);
  // With several data folders each folder is named as found, so the two 1-p001 stay apart.
  CHECK(rows[0].at("folder") == (h1 / "sessions" / "1-p001").string());
  CHECK(rows[0].at("host") == "h1");
  CHECK(rows[0].at("duplicate_uid") == "1");
  CHECK(rows[1].at("duplicate_uid") == "0");
  CHECK(rows[2].at("host") == "h2");
  CHECK(rows[2].at("duplicate_uid") == "1");
  CHECK(row_with(rows, "3-p003").at("duplicate_uid") == "0");
  // Flagged, not dropped: the statistics still count every session.
  CHECK(csv_records(read_text(out / "summary.csv"))[0].at("sessions") == "5");

  const std::string md = read_text(out / "report.md");
  CHECK_THAT(md, Catch::Contains("## Duplicate participants") && Catch::Contains("| p001 | h1, h2 |") &&
                     Catch::Contains("Data folders: "));
  const std::string html = read_text(out / "report.html");
  CHECK_THAT(html, Catch::Contains("<h2>Duplicate participants</h2>") && Catch::Contains("<td>h1, h2</td>"));
}

TEST_CASE("without a host in manager.json, each data folder is a host of its own") {
  ScratchDir scratch;
  const auto a = scratch.path() / "a", b = scratch.path() / "b";
  host_session(a / "sessions" / "1-p001", "p001", std::nullopt);
  host_session(b / "sessions" / "4-p001", "p001", std::nullopt);
  const JobResult result = run_report({a, b}, scratch.path() / "out");
  CHECK(result.exit_status() == 0);
  REQUIRE(result.duplicate_uids.size() == 1);
  const auto rows = csv_records(read_text(scratch.path() / "out" / "sessions.csv"));
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("host") == a.string());
  CHECK(rows[1].at("host") == b.string());
}

TEST_CASE("the same session found twice is reported once, with a note") {
  ScratchDir scratch;
  const auto data = scratch.path() / "data";
  host_session(data / "sessions" / "1-p001", "p001", "h1");
  host_session(data / "sessions" / "2-p002", "p002", "h1");

  SECTION("the same folder given twice") {
    const JobResult result = run_report({data, data}, scratch.path() / "out");
    CHECK(result.exit_status() == 0);
    CHECK(result.sessions_reported == 2);
    REQUIRE(result.repeats.size() == 2);
    CHECK(result.repeats[0].why == "the same folder, under two of the data folders");
    CHECK(result.duplicate_uids.empty());
  }
  SECTION("a host's data folder and the store's copy of it") {
    const auto store = scratch.path() / "store";
    std::filesystem::create_directories(store / "h1");
    std::filesystem::copy(data / "sessions" / "1-p001", store / "h1" / "1-p001");
    const JobResult result = run_report({data, store}, scratch.path() / "out");
    CHECK(result.sessions_reported == 2);
    REQUIRE(result.repeats.size() == 1);
    CHECK(result.repeats[0].folder == (store / "h1" / "1-p001").string());
    CHECK(result.repeats[0].same_as == (data / "sessions" / "1-p001").string());
    CHECK(result.repeats[0].why == "the same host (h1) and folder name");
    CHECK(result.duplicate_uids.empty());
    CHECK_THAT(read_text(scratch.path() / "out" / "report.md"),
               Catch::Contains("## Sessions found twice") && !Catch::Contains("## Duplicate participants"));
  }
  SECTION("a copy whose manager.json names no host: the same name and session.json") {
    host_session(scratch.path() / "old" / "sessions" / "7-p007", "p007", std::nullopt);
    const auto store = scratch.path() / "store";
    std::filesystem::create_directories(store / "h9");
    std::filesystem::copy(scratch.path() / "old" / "sessions" / "7-p007", store / "h9" / "7-p007");
    const JobResult result = run_report({scratch.path() / "old", store}, scratch.path() / "out");
    CHECK(result.sessions_reported == 1);
    REQUIRE(result.repeats.size() == 1);
    CHECK(result.repeats[0].why == "the same folder name and an identical session.json");
    CHECK(result.duplicate_uids.empty());
  }
}

TEST_CASE("the shared store of three hosts is read whole, each session's host from its folder") {
  ScratchDir scratch;
  const auto store = scratch.path() / "store";
  // <store>/<host_id>/<session folder>/ as after_session_command's rsync writes it; no host in manager.json.
  host_session(store / "h1" / "1-a", "a", std::nullopt);
  host_session(store / "h1" / "2-b", "b", std::nullopt);
  host_session(store / "h2" / "1-c", "c", std::nullopt);
  host_session(store / "h3" / "1-d", "d", std::nullopt);
  host_session(store / "h3" / "2-e", "e", std::nullopt);
  // And a host's whole data folder copied under its id.
  host_session(store / "h4" / "sessions" / "1-f", "f", std::nullopt);

  const JobResult result = run_report({store}, scratch.path() / "out");
  CHECK(result.exit_status() == 0);
  CHECK(result.sessions_reported == 6);
  CHECK(result.duplicate_uids.empty());
  const auto rows = csv_records(read_text(scratch.path() / "out" / "sessions.csv"));
  REQUIRE(rows.size() == 6);
  CHECK(row_with(rows, "h1/1-a").at("host") == "h1");
  CHECK(row_with(rows, "h1/1-a").at("folder") == "h1/1-a");  // one data folder: relative, as before
  CHECK(row_with(rows, "h2/1-c").at("host") == "h2");
  CHECK(row_with(rows, "h3/2-e").at("host") == "h3");
  CHECK(row_with(rows, "h4/sessions/1-f").at("host") == "h4");
  CHECK_THAT(read_text(scratch.path() / "out" / "report.md"),
             Catch::Contains("No uid has sessions on more than one host (4 hosts)."));
}

TEST_CASE("a session's host comes from manager.json, else from where its folder lies") {
  using rfbsim::tools::host_from_layout;
  CHECK(host_from_layout("/store", "h2/5-p1") == "h2");
  CHECK(host_from_layout("/store", "h2/sessions/5-p1") == "h2");
  CHECK(host_from_layout("/srv/a/", "sessions/5-p1") == "/srv/a");
  CHECK(host_from_layout("data", ".") == "data");
  CHECK(host_from_layout("data", "5-p1") == "data");

  ScratchDir scratch;
  const auto dir = scratch.path() / "1-p1";
  std::filesystem::create_directories(dir);
  CHECK_FALSE(rfbsim::tools::recorded_host(dir));  // no manager.json
  const auto with_host = [&](const std::string& json) {
    write_text(dir / "manager.json", json);
    return rfbsim::tools::recorded_host(dir);
  };
  CHECK(with_host("{\"host\": \"h7\"}") == std::optional<std::string>("h7"));
  CHECK_FALSE(with_host("{\"host\": 7}"));
  CHECK_FALSE(with_host("{\"host\": \"\"}"));
  CHECK_FALSE(with_host("{\"host\": \"../h1\"}"));
  CHECK_FALSE(with_host("{\"host\": \"" + std::string(65, 'h') + "\"}"));
  CHECK_FALSE(with_host("{\"host\": "));
  CHECK_FALSE(with_host("[1, 2]"));

  // Read in full for the report, a host that is not a string is manager.json's fault like any other key.
  nlohmann::json record = nlohmann::json::parse(manager_json("p1", "finished", 900));
  CHECK_FALSE(parse_manager_record(record.dump(), "m.json").host);  // older managers wrote none
  record["host"] = "h3";
  CHECK(parse_manager_record(record.dump(), "m.json").host == std::optional<std::string>("h3"));
  record["host"] = 3;
  CHECK_THROWS_WITH(parse_manager_record(record.dump(), "m.json"), "m.json: key 'host': expected a string");
}

TEST_CASE("sim_report takes several data folders, writes to the first one's report/ and warns of a duplicate uid") {
  ScratchDir scratch;
  const auto h1 = scratch.path() / "h1", h2 = scratch.path() / "h2";
  host_session(h1 / "sessions" / "1-p001", "p001", "h1");
  host_session(h2 / "sessions" / "1-p001", "p001", "h2");
  host_session(h2 / "sessions" / "2-p002", "p002", "h2");

  CHECK(sim_report(scratch, quoted(h1) + " " + quoted(h2)) == 0);
  const std::string err = read_text(scratch.path() / "stderr.txt");
  CHECK_THAT(err, Catch::Contains("[sim_report] warning: duplicate uid: uid 'p001' has sessions on 2 hosts: h1 (") &&
                      Catch::Contains("; flagged duplicate_uid\n") && Catch::Contains("3 sessions reported, 0 skipped"));
  CHECK(csv_records(read_text(h1 / "report" / "sessions.csv")).size() == 3);

  // The same folder twice: a note, counted once.
  CHECK(sim_report(scratch, quoted(h1) + " " + quoted(h1) + " --out " + quoted(scratch.path() / "out")) == 0);
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"),
             Catch::Contains("[sim_report] note: ") && Catch::Contains("; counted once\n") &&
                 Catch::Contains("1 sessions reported, 0 skipped"));

  // A data folder that is not there is a usage error, whichever it is.
  CHECK(sim_report(scratch, quoted(h1) + " " + quoted(scratch.path() / "missing")) == 2);
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"), Catch::Contains("missing: no such folder"));
}
