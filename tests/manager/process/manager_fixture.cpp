// SPDX-License-Identifier: GPL-2.0-or-later
// ManagerUnderTest and its helpers.
#include "manager_fixture.hpp"

#include <sqlite3.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace rfbsim::test {

std::string sim_manager_path() {
  const char* from_env = std::getenv("RFBSIM_SIM_MANAGER");
  return from_env != nullptr ? from_env : RFBSIM_SIM_MANAGER_DEFAULT;
}

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  std::random_device random;
  path_ = std::filesystem::temp_directory_path() /
          ("rfbsim-manager-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
           std::to_string(random()));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::vector<std::string> small_session_args() {
  return {"--session-arg", "--width", "--session-arg", "320", "--session-arg", "--height",
          "--session-arg", "240",     "--session-arg", "--fps", "--session-arg", "15"};
}

ManagerUnderTest::ManagerUnderTest(const std::filesystem::path& data_dir, const std::vector<std::string>& flags)
    : data_dir_(data_dir) {
  std::vector<std::string> args = {"--port", "0", "--data-dir", data_dir.string()};
  args.insert(args.end(), flags.begin(), flags.end());
  process_ = std::make_unique<SimProcess>(sim_manager_path(), args);
}

net::HttpResponse ManagerUnderTest::start(const std::string& query, bool tls) {
  return net::http_get(port(), "/start?" + query, {}, tls);
}

net::HttpResponse ManagerUnderTest::get(const std::string& target,
                                        const std::vector<std::pair<std::string, std::string>>& headers, bool tls) {
  return net::http_get(port(), target, headers, tls);
}

net::HttpResponse ManagerUnderTest::end_session(std::int64_t id, const std::string& admin_token) {
  const std::string request = "POST /api/sessions/" + std::to_string(id) +
                              "/end HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + admin_token +
                              "\r\nX-Rfbsim-Admin: 1\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
  return net::http_request(port(), request);
}

std::string ManagerUnderTest::state_of(const std::string& token, bool tls) {
  const net::HttpResponse response = get("/s/" + token + "/status", {}, tls);
  const std::string key = "\"state\":\"";
  const std::size_t at = response.body.find(key);
  if (response.status != 200 || at == std::string::npos) return "";
  const std::size_t start = at + key.size();
  return response.body.substr(start, response.body.find('"', start) - start);
}

bool ManagerUnderTest::wait_for_state(const std::string& token, const std::string& state,
                                      std::chrono::milliseconds timeout, bool tls) {
  return eventually([&] { return state_of(token, tls) == state; }, timeout);
}

std::vector<IndexRow> ManagerUnderTest::index_rows() const {
  sqlite3* db = nullptr;
  const std::string path = (data_dir_ / "sessions.db").string();
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    throw std::runtime_error("cannot open " + path);
  }
  sqlite3_busy_timeout(db, 5000);
  sqlite3_stmt* stmt = nullptr;
  const char* sql =
      "SELECT id, uid, token, scenario, params, seed, host_id, state, detail, exit_status, data_path, pid, port, "
      "ready_at IS NOT NULL, ended_at IS NOT NULL FROM sessions ORDER BY id";
  if (sqlite3_prepare_v2(db, sql, -1, &stmt, nullptr) != SQLITE_OK) {
    const std::string message = sqlite3_errmsg(db);
    sqlite3_close(db);
    throw std::runtime_error("index query failed: " + message);
  }
  const auto text = [stmt](int column) {
    const auto* value = sqlite3_column_text(stmt, column);
    return value == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(value));
  };
  std::vector<IndexRow> rows;
  while (sqlite3_step(stmt) == SQLITE_ROW) {
    IndexRow row;
    row.id = sqlite3_column_int64(stmt, 0);
    row.uid = text(1);
    row.token = text(2);
    row.scenario = text(3);
    row.params = text(4);
    row.seed = text(5);
    row.host_id = text(6);
    row.state = text(7);
    row.detail = text(8);
    row.exit_status = text(9);
    row.data_path = text(10);
    row.pid = sqlite3_column_int64(stmt, 11);
    row.port = sqlite3_column_int(stmt, 12);
    row.ready_at_set = sqlite3_column_int(stmt, 13) != 0;
    row.ended_at_set = sqlite3_column_int(stmt, 14) != 0;
    rows.push_back(row);
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return rows;
}

std::optional<IndexRow> ManagerUnderTest::row_for_token(const std::string& token) const {
  for (const IndexRow& row : index_rows()) {
    if (row.token == token) return row;
  }
  return std::nullopt;
}

std::vector<pid_t> ManagerUnderTest::children() const {
  std::vector<pid_t> out;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    const std::size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream fields(line.substr(close + 2));
    std::string state;
    pid_t parent = 0;
    fields >> state >> parent;
    if (parent == pid() && state != "Z") out.push_back(static_cast<pid_t>(std::stoi(name)));
  }
  return out;
}

int ManagerUnderTest::open_descriptors() const {
  int count = 0;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator("/proc/" + std::to_string(pid()) + "/fd", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    ++count;
  }
  return count;
}

double ManagerUnderTest::metric(const std::string& name) {
  const net::HttpResponse response = get("/metrics");
  std::istringstream lines(response.body);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(name + " ", 0) == 0) return std::stod(line.substr(name.size() + 1));
  }
  return -1;
}

std::string token_from_redirect(const net::HttpResponse& response) {
  if (response.status != 302) return "";
  const auto location = response.headers.find("location");
  if (location == response.headers.end()) return "";
  const std::string& value = location->second;
  if (value.size() != 3 + 32 + 1 || value.rfind("/s/", 0) != 0 || value.back() != '/') return "";
  return value.substr(3, 32);
}

bool process_exists(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const std::size_t close = line.rfind(')');
  return close != std::string::npos && line.size() > close + 2 && line[close + 2] != 'Z';
}

bool group_has_running_member(pid_t pgid) {
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    const std::size_t close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream fields(line.substr(close + 2));
    std::string state;
    long parent = 0, group = 0;
    if (fields >> state >> parent >> group && group == pgid && state != "Z") return true;
  }
  return false;
}

std::vector<int> listening_ports() {
  std::vector<int> ports;
  for (const char* file : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::ifstream table(file);
    std::string line;
    std::getline(table, line);  // header
    while (std::getline(table, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, state;
      fields >> slot >> local >> remote >> state;
      if (state != "0A") continue;  // TCP_LISTEN
      ports.push_back(std::stoi(local.substr(local.find(':') + 1), nullptr, 16));
    }
  }
  return ports;
}

bool eventually(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace rfbsim::test
