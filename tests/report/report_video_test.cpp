// SPDX-License-Identifier: GPL-2.0-or-later
// The video condition in the report (issue 33): a watcher's folder (session.json alone) found and reported in
// its own row with empty measures, counted apart from the interactive statistics, and paired with the session
// it watched in pairs.csv, report.md and report.html; a watcher whose source is not in the data is a warning
// naming both, and no pair; a broken watcher's session.json is skipped with the key named.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

#include "report_job.hpp"
#include "session_files.hpp"
#include "sim_report_runner.hpp"
#include "text_format.hpp"

using namespace rfbsim::report;
using namespace rfbsim::report::test;

namespace {

// The start of every hand-made interactive session (session_files.hpp's session_json).
const std::string kSourceStart = "2026-11-24T10:15:02.250Z";

// manager.json of session `id` on host h1, in `condition` (yoked to `yoked_to` when a watcher), link spent.
std::string manager_of(const std::string& uid, int id, const std::string& condition,
                       std::optional<int> yoked_to = std::nullopt) {
  nlohmann::json record = nlohmann::json::parse(manager_json(uid, "finished", 900));
  record["id"] = id;
  record["host"] = "h1";
  record["condition"] = condition;
  record["yoked_to"] = yoked_to ? nlohmann::json(*yoked_to) : nlohmann::json(nullptr);
  record["yoked_to_uid_hash"] = yoked_to ? nlohmann::json("3f2a") : nlohmann::json(nullptr);
  return record.dump() + "\n";
}

// An interactive session `id`-`uid` in `sessions`, with its manager.json: the avatar walks 1 m when `walk`,
// and the task is completed.
void interactive(const std::filesystem::path& sessions, int id, const std::string& uid, bool walk) {
  SessionSpec spec = small_session();
  spec.uid = uid;
  spec.outcome = "completed";
  if (walk) spec.tracks[0].at = [](double t) { return State{1.0 + std::min(t, 1.0), 1.0, 0.0, 0.0, 0.0}; };
  const auto dir = sessions / (std::to_string(id) + "-" + uid);
  write_session(dir, spec);
  nlohmann::json doc = session_json(spec);
  doc["condition"] = "interactive";  // as sim_rfb writes it since issue 33 (older files lack it)
  write_text(dir / "session.json", doc.dump(2) + "\n");
  write_text(dir / "manager.json", manager_of(uid, id, "interactive"));
}

// A watcher's session.json as docs/data.md describes it: yoked to `yoked_to`, watched for 33 s to the end of
// the recording's 60 ticks (`watched`), or stopped by a signal after 12.5 s at tick 30.
nlohmann::json watcher_json(const std::string& uid, std::optional<int> yoked_to, bool watched = true) {
  return {{"kind", "replay"},
          {"condition", "video"},
          {"uid", uid},
          {"yoked_to", yoked_to ? nlohmann::json(*yoked_to) : nlohmann::json(nullptr)},
          {"yoked_to_uid_hash", "3f2a"},
          {"scenario", "lab"},
          {"camera", "third_person"},
          {"replay_of",
           {{"uid_hash", "3f2a"},
            {"scenario", "lab"},
            {"seed", "42"},
            {"started_at", kSourceStart},
            {"end_tick", 60},
            {"end_reason", "completed"},
            {"outcome", "completed"}}},
          {"versions", {{"rfbsim", "0.1.0"}, {"build", "test"}}},
          {"started_at", "2026-11-29T10:05:00.000Z"},
          {"ended_at", watched ? "2026-11-29T10:05:33.000Z" : "2026-11-29T10:05:12.500Z"},
          {"end_tick", watched ? 60 : 30},
          {"end_reason", watched ? "watched" : "signal"},
          {"outcome", watched ? nlohmann::json("watched") : nlohmann::json(nullptr)},
          {"viewers", 1}};
}

// A watcher's folder `id`-`uid`: its session.json, sim_manager's session.log and manager.json, nothing else.
void watcher(const std::filesystem::path& sessions, int id, const std::string& uid, const nlohmann::json& doc) {
  const auto dir = sessions / (std::to_string(id) + "-" + uid);
  write_text(dir / "session.json", doc.dump(2) + "\n");
  write_text(dir / "session.log", "[sim_rfb] replaying\n");
  const nlohmann::json yoked = doc.value("yoked_to", nlohmann::json());
  const std::optional<int> source = yoked.is_number_integer() ? std::optional<int>(yoked.get<int>()) : std::nullopt;
  write_text(dir / "manager.json", manager_of(uid, id, "video", source));
}

}  // namespace

TEST_CASE("watchers are reported in rows of their own, kept out of the statistics and paired with their sources") {
  ScratchDir scratch;
  const auto sessions = scratch.path() / "sessions";
  // Two interactive sessions (12 walked, 13 stood still) and three watchers: 14 and 15 of 12, 11 of 13.
  interactive(sessions, 12, "pA", true);
  interactive(sessions, 13, "pC", false);
  watcher(sessions, 14, "pB", watcher_json("pB", 12));
  watcher(sessions, 15, "pD", watcher_json("pD", 12, false));
  watcher(sessions, 11, "pE", watcher_json("pE", 13));

  const auto out = scratch.path() / "report";
  const JobResult result = run_report(scratch.path(), out);
  CHECK(result.exit_status() == 0);
  CHECK(result.skipped.empty());
  CHECK(result.warnings.empty());
  CHECK(result.sessions_reported == 5);
  CHECK(result.sessions_excluded == 0);
  CHECK(result.video_sessions == 3);
  CHECK(result.video_pairs == 3);

  // sessions.csv: the condition and the source of each row; a watcher's measures are empty, not 0.
  const auto rows = csv_records(read_text(out / "sessions.csv"));
  REQUIRE(rows.size() == 5);
  const auto& a = row_of(rows, "pA");
  CHECK(a.at("condition") == "interactive");
  CHECK(a.at("yoked_to").empty());
  CHECK(a.at("session_id") == "12");
  CHECK(a.at("in_statistics") == "1");
  CHECK(a.at("avatar_path_length") == "1");
  const auto& b = row_of(rows, "pB");
  CHECK(b.at("condition") == "video");
  CHECK(b.at("yoked_to") == "12");
  CHECK(b.at("session_id") == "14");
  CHECK(b.at("scenario") == "lab");
  CHECK(b.at("host") == "h1");
  CHECK(b.at("outcome") == "watched");
  CHECK(b.at("end_reason") == "watched");
  CHECK(b.at("in_statistics") == "0");
  CHECK(b.at("manager_state") == "finished");
  for (const char* measure : {"duration", "samples", "avatar_path_length", "never_moved", "found_robot",
                              "min_robot_avatar_distance", "robot_within_1_2", "robot_path_length", "data_complete"}) {
    INFO(measure);
    CHECK(b.at(measure).empty());
  }
  CHECK(row_of(rows, "pD").at("outcome").empty());  // stopped before the end

  // summary.csv: N is the two interactive sessions; the watchers are counted apart, not left out.
  const auto groups = csv_records(read_text(out / "summary.csv"));
  REQUIRE(groups.size() == 2);
  for (const auto& g : groups) {
    CHECK(g.at("sessions") == "2");
    CHECK(g.at("excluded_sessions") == "0");
    CHECK(g.at("video_sessions") == "3");
    CHECK(g.at("duration_n") == "2");
    CHECK(std::stod(g.at("pct_completed")) == Approx(100.0));
    CHECK(std::stod(g.at("pct_never_moved")) == Approx(50.0));
    CHECK(std::stod(g.at("avatar_path_length_mean")) == Approx(0.5));
  }

  // pairs.csv: one row per pair, by the source's id, then the watcher's, with the source's measures.
  const auto pairs = csv_records(read_text(out / "pairs.csv"));
  REQUIRE(pairs.size() == 3);
  CHECK(pairs[0].at("pair") == "1");
  CHECK(pairs[0].at("host") == "h1");
  CHECK(pairs[0].at("scenario") == "lab");
  CHECK(pairs[0].at("source_session") == "12");
  CHECK(pairs[0].at("source_uid") == "pA");
  CHECK(pairs[0].at("source_folder") == "sessions/12-pA");
  CHECK(pairs[0].at("watcher_session") == "14");
  CHECK(pairs[0].at("watcher_uid") == "pB");
  CHECK(pairs[0].at("watcher_folder") == "sessions/14-pB");
  CHECK(pairs[0].at("watcher_outcome") == "watched");
  CHECK(pairs[0].at("watcher_watched_s") == "33");
  CHECK(pairs[0].at("watcher_shown_pct") == "100");
  CHECK(pairs[0].at("source_outcome") == "completed");
  CHECK(pairs[0].at("source_in_statistics") == "1");
  // Every measure of A, exactly as its sessions.csv row has it.
  std::size_t measures = 0;
  for (const auto& [name, cell] : a) {
    if (pairs[0].count("source_" + name) == 0 || name == "outcome" || name == "in_statistics") continue;
    INFO(name);
    CHECK(pairs[0].at("source_" + name) == cell);
    ++measures;
  }
  CHECK(measures > 50);
  CHECK(pairs[0].at("source_avatar_path_length") == "1");
  CHECK(pairs[1].at("source_session") == "12");
  CHECK(pairs[1].at("watcher_session") == "15");
  CHECK(pairs[1].at("watcher_outcome").empty());
  CHECK(pairs[1].at("watcher_end_reason") == "signal");
  CHECK(pairs[1].at("watcher_watched_s") == "12.5");
  CHECK(pairs[1].at("watcher_shown_pct") == "50");
  CHECK(pairs[2].at("pair") == "3");
  CHECK(pairs[2].at("source_session") == "13");
  CHECK(pairs[2].at("source_uid") == "pC");
  CHECK(pairs[2].at("watcher_session") == "11");
  CHECK(pairs[2].at("source_avatar_path_length") == "0");

  // report.md and report.html: the count of pairs in the section's header, and the watchers counted apart.
  const std::string md = read_text(out / "report.md");
  CHECK_THAT(md, Catch::Contains("5 sessions reported (2 in the statistics, 0 without a participant left out, "
                                 "3 watchers (video condition) counted apart), 0 skipped"));
  CHECK_THAT(md, Catch::Contains("## Video condition: 3 pairs\n"));
  CHECK_THAT(md, Catch::Contains("| 1 | h1 | lab | 12 | pA | 14 | pB | watched | 33.000 | completed |"));
  CHECK_THAT(md, Catch::Contains("| 3 | h1 | lab | 13 | pC | 11 | pE | watched |"));
  CHECK_THAT(md, Catch::Contains("| all sessions | 2 | 0 |"));
  CHECK(md.find("## Left out of the statistics") == std::string::npos);
  const std::string html = read_text(out / "report.html");
  CHECK_THAT(html, Catch::Contains("<h2>Video condition: 3 pairs</h2>"));
  CHECK_THAT(html, Catch::Contains("<td>pA</td><td class=\"n\">14</td><td>pB</td><td>watched</td>"));
  CHECK(html.find("sessions/14-pB &#8212;") == std::string::npos);  // no trajectory plot for a watcher
  CHECK_THAT(html, Catch::Contains("sessions/12-pA &#8212;"));

  // The real binary says how many pairs on stderr.
  CHECK(sim_report(scratch, quoted(scratch.path()) + " --out " + quoted(scratch.path() / "out2")) == 0);
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"),
             Catch::Contains("[sim_report] 3 video-condition pairs") &&
                 Catch::Contains("5 sessions reported, 0 skipped"));
  CHECK_THAT(read_text(scratch.path() / "stdout.txt"), Catch::Contains("pairs.csv"));
}

TEST_CASE("a watcher whose source is not in the data is a warning naming both, and makes no pair") {
  ScratchDir scratch;
  const auto sessions = scratch.path() / "sessions";
  interactive(sessions, 12, "pA", true);
  watcher(sessions, 14, "pB", watcher_json("pB", 99));  // session 99 is not here
  nlohmann::json later = watcher_json("pF", 12);        // a session 12 that started at another time
  later["replay_of"]["started_at"] = "2026-12-01T09:00:00.000Z";
  watcher(sessions, 16, "pF", later);
  watcher(sessions, 17, "pG", watcher_json("pG", std::nullopt));  // sim_rfb --replay run by hand

  const auto out = scratch.path() / "report";
  const JobResult result = run_report(scratch.path(), out);
  CHECK(result.exit_status() == 0);  // warnings leave it as it is
  CHECK(result.sessions_reported == 4);
  CHECK(result.video_sessions == 3);
  CHECK(result.video_pairs == 0);
  REQUIRE(result.warnings.size() == 3);
  CHECK(result.warnings[0] ==
        "watcher sessions/14-pB (uid 'pB', host h1) watched session 99 on host h1, which is not in the data: no pair");
  CHECK(result.warnings[1] ==
        "watcher sessions/16-pF (uid 'pF', host h1) watched session 12 on host h1, which is not sessions/12-pA "
        "(uid 'pA', host h1) (that one started at " + kSourceStart +
            ", the one watched at 2026-12-01T09:00:00.000Z): no pair");
  CHECK(result.warnings[2] == "watcher sessions/17-pG (uid 'pG', host h1) watched a recording sim_rfb was given by "
                              "hand (yoked_to null): no pair");

  // The watchers keep their rows; pairs.csv has its header alone.
  const auto rows = csv_records(read_text(out / "sessions.csv"));
  CHECK(row_of(rows, "pB").at("yoked_to") == "99");
  CHECK(row_of(rows, "pG").at("yoked_to").empty());
  const std::string pairs = read_text(out / "pairs.csv");
  CHECK(csv_records(pairs).empty());
  CHECK_THAT(pairs, Catch::StartsWith("pair,host,scenario,source_session,source_uid,"));
  const std::string md = read_text(out / "report.md");
  CHECK_THAT(md, Catch::Contains("## Video condition: 0 pairs") &&
                     Catch::Contains(markdown_escape("3 watchers' sessions, 0 paired, 3 not (each under Warnings, "
                                                     "with why).")) &&
                     !Catch::Contains("| pair |") &&
                     Catch::Contains("## Warnings"));

  // A source on another host is another session, however alike its id.
  ScratchDir other;
  interactive(other.path() / "h2" / "sessions", 12, "pA", true);
  watcher(other.path() / "h1" / "sessions", 14, "pB", watcher_json("pB", 12));
  const auto a_manager = other.path() / "h2" / "sessions" / "12-pA" / "manager.json";
  nlohmann::json a_record = nlohmann::json::parse(read_text(a_manager));
  a_record["host"] = "h2";
  write_text(a_manager, a_record.dump());
  const JobResult apart = run_report({other.path() / "h1", other.path() / "h2"}, other.path() / "report");
  CHECK(apart.video_pairs == 0);
  REQUIRE(apart.warnings.size() == 1);
  CHECK_THAT(apart.warnings[0], Catch::Contains("watched session 12 on host h1, which is not in the data: no pair"));

  // The binary warns of it on stderr, and counts no pair.
  CHECK(sim_report(scratch, quoted(scratch.path()) + " --out " + quoted(scratch.path() / "out2")) == 0);
  CHECK_THAT(read_text(scratch.path() / "stderr.txt"),
             Catch::Contains("[sim_report] warning: watcher sessions/14-pB (uid 'pB', host h1) watched session 99") &&
                 Catch::Contains("[sim_report] 0 video-condition pairs"));
}

TEST_CASE("a watcher's session.json is recognised before the strict reader, and a broken one is skipped with why") {
  ScratchDir scratch;
  const auto sessions = scratch.path() / "sessions";
  interactive(sessions, 12, "pA", true);
  // Recognised by its kind alone (no condition key), and by its condition alone.
  nlohmann::json by_kind = watcher_json("pB", 12);
  by_kind.erase("condition");
  watcher(sessions, 14, "pB", by_kind);
  nlohmann::json by_condition = watcher_json("pH", 12);
  by_condition.erase("kind");
  watcher(sessions, 18, "pH", by_condition);
  // Broken: yoked_to of the wrong type; no replay_of; a condition nobody knows.
  nlohmann::json wrong = watcher_json("pX", 12);
  wrong["yoked_to"] = "12";
  watcher(sessions, 20, "pX", wrong);
  nlohmann::json no_source = watcher_json("pY", 12);
  no_source.erase("replay_of");
  watcher(sessions, 21, "pY", no_source);
  nlohmann::json unknown = watcher_json("pZ", 12);
  unknown["condition"] = "audio";
  write_text(sessions / "22-pZ" / "session.json", unknown.dump());

  const auto out = scratch.path() / "report";
  const JobResult result = run_report(scratch.path(), out);
  CHECK(result.exit_status() == 1);  // skipped sessions are data errors
  CHECK(result.sessions_reported == 3);
  CHECK(result.video_pairs == 2);
  REQUIRE(result.skipped.size() == 3);
  CHECK(result.skipped[0].folder == "sessions/20-pX");
  CHECK(result.skipped[0].reason == (sessions / "20-pX" / "session.json").string() +
                                        ": key 'yoked_to': expected an integer or null");
  CHECK(result.skipped[1].reason == (sessions / "21-pY" / "session.json").string() + ": key 'replay_of': missing");
  CHECK_THAT(result.skipped[2].reason, Catch::Contains("key 'condition': 'audio' is neither interactive nor video"));
  // A manager.json that disagrees with session.json is a warning; session.json decides.
  write_text(sessions / "18-pH" / "manager.json", manager_of("pH", 18, "interactive"));
  const JobResult disagreeing = run_report(scratch.path(), out);
  REQUIRE(disagreeing.warnings.size() == 1);
  CHECK_THAT(disagreeing.warnings[0], Catch::EndsWith("manager.json: condition 'interactive', but session.json is a "
                                                      "watcher's (video); reported as session.json says"));
  CHECK(disagreeing.video_pairs == 2);
}
