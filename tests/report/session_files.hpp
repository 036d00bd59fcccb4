// SPDX-License-Identifier: GPL-2.0-or-later
// Test helpers: a scratch folder per test, session folders written as docs/data.md describes from
// hand-made tracks (a position and velocity per agent as functions of time), sim_manager's manager.json,
// and a small CSV parser.
#pragma once

#include <stdlib.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "file_text.hpp"
#include "scratch_dir.hpp"

namespace rfbsim::report::test {

using rfbsim::test::ScratchDir;  // tests/support: a fresh folder per test, removed at scope exit

using rfbsim::test::write_text;  // tests/support/file_text.hpp

/// The whole content of `file` ("" when it cannot be read).
inline std::string read_text(const std::filesystem::path& file) { return rfbsim::test::file_text(file); }

/// Pi, for the hand-made tracks' angles.
inline constexpr double kPi = std::numbers::pi;

/// Where an agent is at simulated time t: position (m), yaw (rad), velocity (m/s).
struct State {
  double x = 0.0, y = 0.0, yaw = 0.0, vx = 0.0, vy = 0.0;
};

/// One agent of a hand-made session.
struct Track {
  std::string kind;  ///< avatar, robot or person
  int id = 0;
  double radius = 0.3;
  std::function<State(double t)> at;
};

/// An agent standing still at (x, y).
inline Track standing(const std::string& kind, int id, double radius, double x, double y) {
  return {kind, id, radius, [=](double) { return State{x, y, 0.0, 0.0, 0.0}; }};
}

/// A hand-made session: its tracks are sampled at trajectory_hz for `samples` samples.
struct SessionSpec {
  std::string uid = "p001";
  std::string scenario = "lab";
  std::string scenario_file;
  int tick_hz = 60;
  int trajectory_hz = 10;
  int samples = 121;
  std::vector<Track> tracks;        ///< avatar first, then robot, then people, as the writer orders them
  std::vector<nlohmann::json> events;  ///< each with tick, time, type and its keys
  std::optional<std::string> outcome;
  std::optional<std::uint64_t> end_tick;
  std::optional<std::string> data_incomplete;  ///< session.json's data_incomplete.reason, when the recording failed
  std::uint64_t dropped_bytes = 0;             ///< and its dropped_bytes
};

/// An event line's object: tick, time (tick / 60) and type first, then `fields`.
inline nlohmann::json event(std::uint64_t tick, const std::string& type, const nlohmann::json& fields = {}) {
  nlohmann::json e = {{"tick", tick}, {"time", static_cast<double>(tick) / 60.0}, {"type", type}};
  if (fields.is_object()) e.update(fields);
  return e;
}

/// session.json for `spec`, as the writer makes it.
inline nlohmann::json session_json(const SessionSpec& spec) {
  nlohmann::json agents = nlohmann::json::array();
  for (const Track& t : spec.tracks) agents.push_back({{"kind", t.kind}, {"id", t.id}, {"radius", t.radius}});
  nlohmann::json doc = {{"format", "rfbsim-session/1"},
          {"uid", spec.uid},
          {"scenario", spec.scenario},
          {"scenario_file", spec.scenario_file},
          {"parameters", {{"crowd", "1"}}},
          {"seed", "18446744073709551615"},
          {"tick_hz", spec.tick_hz},
          {"fps", 30},
          {"trajectory_hz", spec.trajectory_hz},
          {"frame", {{"width", 1280}, {"height", 720}}},
          {"versions", {{"rfbsim", "0.1.0"}, {"build", "test"}, {"scenario_sha256", ""}, {"map_sha256", ""}}},
          {"agents", agents},
          {"tasks", {{{"type", "find_robot"}, {"text", "Find the robot"}}}},
          {"time_limit_s", 240.0},
          {"codes", {{"success", "C1"}, {"timeout", "T1"}}},
          {"started_at", "2026-11-24T10:15:02.250Z"},
          {"ended_at", spec.end_tick ? nlohmann::json("2026-11-24T10:19:20.004Z") : nlohmann::json(nullptr)},
          {"end_tick", spec.end_tick ? nlohmann::json(*spec.end_tick) : nlohmann::json(nullptr)},
          {"end_reason", spec.end_tick ? nlohmann::json("completed") : nlohmann::json(nullptr)},
          {"outcome", spec.outcome ? nlohmann::json(*spec.outcome) : nlohmann::json(nullptr)},
          {"completion", nullptr},
          {"tasks_done", nlohmann::json::array()}};
  if (spec.data_incomplete) {
    doc["data_incomplete"] = {{"reason", *spec.data_incomplete}, {"dropped_bytes", spec.dropped_bytes}};
  }
  return doc;
}

/// manager.json as sim_manager writes it beside a session's data: created at 2026-11-25T10:00:00.000Z,
/// spent `spent_after_ms` later (null when none), with `data_incomplete` (null when none).
inline std::string manager_json(const std::string& uid, const std::string& state,
                                std::optional<int> spent_after_ms = std::nullopt,
                                std::optional<std::string> data_incomplete = std::nullopt) {
  const auto at = [](int ms) {
    char text[40];
    std::snprintf(text, sizeof text, "2026-11-25T10:%02d:%02d.%03dZ", ms / 60000, ms / 1000 % 60, ms % 1000);
    return nlohmann::json(text);
  };
  const nlohmann::json doc = {
      {"id", 3},
      {"uid", uid},
      {"state", state},
      {"detail", state == "abandoned" ? "no browser connected for 60 s" : ""},
      {"created_at", at(0)},
      {"ready_at", at(300)},
      {"spent_at", spent_after_ms ? at(*spent_after_ms) : nlohmann::json(nullptr)},
      {"ended_at", at(59000)},
      {"outcome", nullptr},
      {"data_incomplete", data_incomplete ? nlohmann::json(*data_incomplete) : nlohmann::json(nullptr)}};
  return doc.dump() + "\n";
}

/// trajectories.csv for `spec`, six decimals as the writer prints them.
inline std::string trajectory_csv(const SessionSpec& spec) {
  std::string out = "tick,time,kind,id,x,y,yaw,vx,vy\n";
  const int every = spec.tick_hz / spec.trajectory_hz;
  for (int k = 0; k < spec.samples; ++k) {
    const long tick = static_cast<long>(k) * every;
    const double t = static_cast<double>(tick) / spec.tick_hz;
    for (const Track& track : spec.tracks) {
      const State s = track.at(t);
      char row[256];
      std::snprintf(row, sizeof row, "%ld,%.6f,%s,%d,%.6f,%.6f,%.6f,%.6f,%.6f\n", tick, t, track.kind.c_str(), track.id,
                    s.x, s.y, s.yaw, s.vx, s.vy);
      out += row;
    }
  }
  return out;
}

/// Writes the three files of `spec` into `dir`.
inline void write_session(const std::filesystem::path& dir, const SessionSpec& spec) {
  write_text(dir / "session.json", session_json(spec).dump(2) + "\n");
  write_text(dir / "trajectories.csv", trajectory_csv(spec));
  std::string events;
  for (const nlohmann::json& e : spec.events) events += e.dump() + "\n";
  write_text(dir / "events.jsonl", events);
}

/// A small session that reads cleanly: avatar, robot and one person standing, 11 samples.
inline SessionSpec small_session() {
  SessionSpec spec;
  spec.samples = 11;
  spec.tracks = {standing("avatar", 0, 0.3, 1.0, 1.0), standing("robot", 0, 0.16, 3.0, 1.0),
                 standing("person", 1, 0.25, 5.0, 5.0)};
  spec.events = {event(0, "session", {{"event", "start"}})};
  spec.end_tick = 60;
  return spec;
}

/// RFC 4180 CSV: rows of fields, quotes undone.
inline std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> row;
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      row.push_back(field);
      field.clear();
    } else if (c == '\n') {
      row.push_back(field);
      field.clear();
      rows.push_back(row);
      row.clear();
    } else {
      field += c;
    }
  }
  return rows;
}

/// The CSV's rows as maps from the header's names to the cells.
inline std::vector<std::map<std::string, std::string>> csv_records(const std::string& text) {
  const auto rows = parse_csv(text);
  std::vector<std::map<std::string, std::string>> out;
  for (std::size_t r = 1; r < rows.size(); ++r) {
    if (rows[r].size() != rows[0].size()) throw std::runtime_error("CSV row " + std::to_string(r) + ": wrong width");
    std::map<std::string, std::string> record;
    for (std::size_t c = 0; c < rows[0].size(); ++c) record[rows[0][c]] = rows[r][c];
    out.push_back(record);
  }
  return out;
}

/// The record of `rows` (csv_records) whose uid column is `uid`; throws when there is none.
inline const std::map<std::string, std::string>& row_of(const std::vector<std::map<std::string, std::string>>& rows,
                                                        const std::string& uid) {
  const auto it = std::find_if(rows.begin(), rows.end(), [&](const auto& r) { return r.at("uid") == uid; });
  if (it == rows.end()) throw std::runtime_error("no row for uid '" + uid + "'");
  return *it;
}

}  // namespace rfbsim::report::test
