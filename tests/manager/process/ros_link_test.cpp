// SPDX-License-Identifier: GPL-2.0-or-later
// ROS under sim_manager (issue 20), through a real sim_manager process: a link's robot_control and the config's
// ros section reach the session's command line (never --rosbridge-port), a link that cannot work is refused with
// 400, signed links cover the setting, and the researcher (admin API, index, manager.json) sees the session's
// ROS namespace while the participant's status poll does not. The session program is a stand-in for sim_rfb
// that records its arguments and reports ready: what is tested is the manager's side, not sim_rfb's bridge.
#include <catch2/catch.hpp>

#include <sqlite3.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "manager_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::kAdminToken;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;

namespace fs = std::filesystem;

namespace {

constexpr const char* kLinkSecret = "ros-link-secret-0123456789";

// Writes `text` to `path` with `mode`.
void write_file(const fs::path& path, const std::string& text, fs::perms mode = fs::perms::owner_read |
                                                                                 fs::perms::owner_write) {
  std::ofstream(path, std::ios::binary) << text;
  fs::permissions(path, mode);
}

// A stand-in for sim_rfb in `dir`: writes its arguments one per line to argv.txt in its working folder (the
// session's), reports ready on the unix socket it was told, and waits to be stopped.
std::string fake_sim(const fs::path& dir) {
  const fs::path script = dir / "fake_sim_rfb.sh";
  write_file(script,
             "#!/bin/sh\n"
             "printf '%s\\n' \"$@\" > argv.txt\n"
             "sock=\n"
             "while [ $# -gt 0 ]; do\n"
             "  if [ \"$1\" = --unix-socket ]; then sock=$2; fi\n"
             "  shift\n"
             "done\n"
             "echo \"ready unix $sock\" >&3\n"
             "exec sleep 120\n",
             fs::perms::owner_all);
  return script.string();
}

// Two scenarios as the manager reads them: depot has a robot, hall has none.
std::string scenarios(const fs::path& dir) {
  write_file(dir / "depot.yaml", "name: depot\nspawns:\n  dock: [1, 2, 0]\nrobot:\n  start: dock\n");
  write_file(dir / "hall.yaml", "name: hall\nspawns:\n  door: [0, 0, 0]\n");
  return "depot=" + (dir / "depot.yaml").string() + ",hall=" + (dir / "hall.yaml").string();
}

// The session's arguments as the stand-in recorded them, once it is running.
std::vector<std::string> argv_of(const ManagerUnderTest& manager, const std::string& token) {
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  std::ifstream in(fs::path(row->data_path) / "argv.txt");
  std::vector<std::string> args;
  for (std::string line; std::getline(in, line);) args.push_back(line);
  REQUIRE_FALSE(args.empty());
  return args;
}

// The value after `flag` in `args` ("" when absent), and how often the flag appears.
std::string value_after(const std::vector<std::string>& args, const std::string& flag) {
  const auto at = std::find(args.begin(), args.end(), flag);
  return at == args.end() || at + 1 == args.end() ? std::string() : *(at + 1);
}
long count_of(const std::vector<std::string>& args, const std::string& flag) {
  return std::count(args.begin(), args.end(), flag);
}

// The index's ROS columns of the session with `token`, read with a connection of our own.
std::string ros_columns(const fs::path& data_dir, const std::string& token) {
  sqlite3* db = nullptr;
  const std::string path = (data_dir / "sessions.db").string();
  REQUIRE(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  REQUIRE(sqlite3_prepare_v2(db, "SELECT ros_namespace || '|' || robot_control FROM sessions WHERE token = ?", -1,
                             &stmt, nullptr) == SQLITE_OK);
  sqlite3_bind_text(stmt, 1, token.c_str(), -1, SQLITE_TRANSIENT);
  std::string text = "?";
  if (sqlite3_step(stmt) == SQLITE_ROW) text = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return text;
}

}  // namespace

TEST_CASE("with a ros section a robot session dials out to the lab under its namespace, and only the researcher sees it",
          "[manager][ros]") {
  TempDir data;
  TempDir files("rfbsim-ros-files");
  write_file(files.path() / "rosbridge.token", "lab-token-0123456789\n");
  write_file(files.path() / "lab-ca.pem", "-----BEGIN CERTIFICATE-----\nMIIB\n-----END CERTIFICATE-----\n");
  write_file(files.path() / "manager.yaml", "ros:\n"
                                            "  connect: wss://ros.lab.example.org:9090/\n"
                                            "  token_file: " + (files.path() / "rosbridge.token").string() + "\n"
                                            "  ca_file: " + (files.path() / "lab-ca.pem").string() + "\n"
                                            "  namespace: /lab/study\n");
  ManagerUnderTest manager(data.path(), rfbsim::test::without_abuse_limits(
                                            {"--config", (files.path() / "manager.yaml").string(), "--session-command",
                                             fake_sim(files.path()), "--scenarios", scenarios(files.path()),
                                             "--admin-token", kAdminToken}));

  // A robot scenario with the link's robot_control: the lab's stack drives it, under s_<id>.
  const std::string external = token_from_redirect(manager.start("uid=ros-1&scenario=depot&robot_control=external"));
  const auto args = argv_of(manager, external);
  const auto row = manager.row_for_token(external);
  REQUIRE(row);
  const std::string ros_namespace = "/lab/study/s_" + std::to_string(row->id);
  CHECK(value_after(args, "--robot-control") == "external");
  CHECK(count_of(args, "--robot-control") == 1);
  CHECK(value_after(args, "--rosbridge-connect") == "wss://ros.lab.example.org:9090/");
  CHECK(value_after(args, "--ros-namespace") == ros_namespace);
  CHECK(value_after(args, "--rosbridge-token-file") == (files.path() / "rosbridge.token").string());
  CHECK(value_after(args, "--rosbridge-ca") == (files.path() / "lab-ca.pem").string());
  // sim_rfb's own rosbridge server has no authentication: never opened under the manager.
  CHECK(count_of(args, "--rosbridge-port") == 0);
  CHECK(count_of(args, "--rosbridge-bind") == 0);
  // The token's text stays in its file.
  for (const std::string& arg : args) CHECK(arg.find("lab-token") == std::string::npos);
  CHECK(ros_columns(data.path(), external) == ros_namespace + "|external");

  // The same scenario without the setting: the section's default, builtin.
  const std::string builtin = token_from_redirect(manager.start("uid=ros-2&scenario=depot"));
  const auto builtin_args = argv_of(manager, builtin);
  CHECK(value_after(builtin_args, "--robot-control") == "builtin");
  CHECK(count_of(builtin_args, "--rosbridge-connect") == 1);

  // A scenario without a robot: refused with the setting, and no ROS without it.
  const auto refused = manager.start("uid=ros-3&scenario=hall&robot_control=external");
  CHECK(refused.status == 400);
  CHECK(refused.body.find("robot_control is not valid here: scenario hall has no robot") != std::string::npos);
  const std::string hall = token_from_redirect(manager.start("uid=ros-4&scenario=hall"));
  const auto hall_args = argv_of(manager, hall);
  CHECK(count_of(hall_args, "--rosbridge-connect") == 0);
  CHECK(count_of(hall_args, "--ros-namespace") == 0);
  CHECK(count_of(hall_args, "--robot-control") == 0);
  CHECK(ros_columns(data.path(), hall) == "|");

  // The researcher: the admin API names the namespace and who drives.
  const auto list = nlohmann::json::parse(
      manager.get("/api/sessions", {{"Authorization", std::string("Bearer ") + kAdminToken}}).body, nullptr, false);
  REQUIRE(list.is_object());
  int seen = 0;
  for (const auto& s : list["live"]) {
    if (s.value("uid", "") == "ros-1") {
      CHECK(s["ros_namespace"] == ros_namespace);
      CHECK(s["robot_control"] == "external");
      ++seen;
    } else if (s.value("uid", "") == "ros-4") {
      CHECK(s["ros_namespace"].is_null());
      CHECK(s["robot_control"].is_null());
      ++seen;
    }
  }
  CHECK(seen == 2);
  // ... and so does the session's manager.json beside its data.
  const fs::path record = fs::path(row->data_path) / "manager.json";
  REQUIRE(rfbsim::test::eventually([&] { return fs::exists(record); }, 10s));
  std::ifstream in(record);
  const auto json = nlohmann::json::parse(in, nullptr, false);
  REQUIRE(json.is_object());
  CHECK(json["ros_namespace"] == ros_namespace);
  CHECK(json["robot_control"] == "external");

  // The participant's status poll tells nothing of the lab's ROS.
  const auto status = manager.get("/s/" + external + "/status");
  REQUIRE(status.status == 200);
  INFO(status.body);
  CHECK(status.body.find("ros_namespace") == std::string::npos);
  CHECK(status.body.find("robot") == std::string::npos);
  CHECK(status.body.find("external") == std::string::npos);
  CHECK(status.body.find("/lab/study") == std::string::npos);
}

TEST_CASE("without a ros section robot_control external is refused, builtin passes, and a signature covers it",
          "[manager][ros]") {
  TempDir data;
  TempDir files("rfbsim-ros-files");
  ManagerUnderTest manager(data.path(), rfbsim::test::without_abuse_limits(
                                            {"--session-command", fake_sim(files.path()), "--scenarios",
                                             scenarios(files.path()), "--link-secret", kLinkSecret}));
  const auto sign = [](const std::string& query) {
    const auto signed_link =
        rfbsim::test::run_to_exit(rfbsim::test::sim_manager_path(), {"--link-secret", kLinkSecret, "--sign", query});
    REQUIRE(signed_link.output.size() > 1);
    return signed_link.output.substr(0, signed_link.output.size() - 1);
  };
  // Nothing would drive the robot: a clear 400 before any process starts.
  const auto refused = manager.start(sign("uid=rc-1&scenario=depot&robot_control=external"));
  CHECK(refused.status == 400);
  CHECK(refused.body.find("robot_control external is not offered here") != std::string::npos);
  CHECK(manager.index_rows().empty());

  // builtin reaches the session, with nothing of ROS.
  const std::string link = sign("uid=rc-2&scenario=depot&robot_control=builtin");
  const auto args = argv_of(manager, token_from_redirect(manager.start(link)));
  CHECK(value_after(args, "--robot-control") == "builtin");
  CHECK(count_of(args, "--rosbridge-connect") == 0);
  CHECK(count_of(args, "--ros-namespace") == 0);

  // The setting is signed with the rest: changed after signing, the link is refused.
  std::string tampered = sign("uid=rc-3&scenario=depot&robot_control=builtin");
  tampered.replace(tampered.find("robot_control=builtin"), 21, "robot_control=external");
  CHECK(manager.start(tampered).status == 403);
}
