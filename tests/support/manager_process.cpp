// SPDX-License-Identifier: GPL-2.0-or-later
// ManagerUnderTest and its helpers: HTTP on loopback, the index through SQLite, processes through /proc.
#include "manager_process.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sqlite3.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace rfbsim::test {

namespace {

// The fields of /proc/<pid>/stat that the helpers here read.
struct ProcStat {
  pid_t pid = 0;
  char state = '?';  // R, S, D, Z (zombie), ...
  pid_t parent = 0;
  pid_t group = 0;
};

// One process's stat line; nullopt once it is gone. The command name before the fields is in parentheses
// and may itself hold spaces and ')', so the fields are read after the last ')'.
std::optional<ProcStat> read_proc_stat(pid_t pid) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(file, line)) return std::nullopt;
  const std::size_t close = line.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  std::istringstream fields(line.substr(close + 1));
  ProcStat stat;
  stat.pid = pid;
  if (!(fields >> stat.state >> stat.parent >> stat.group)) return std::nullopt;
  return stat;
}

// A TCP socket in LISTEN state: its local port and its inode (how /proc/*/fd names it).
struct ListeningSocket {
  int port = 0;
  std::string inode;
};

// Every listening TCP socket on this machine, IPv4 and IPv6 (/proc/net/tcp's columns: slot, local and remote
// address, state, queues, timer, retransmits, uid, timeout, inode).
std::vector<ListeningSocket> listening_sockets() {
  std::vector<ListeningSocket> sockets;
  for (const char* file : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::ifstream table(file);
    std::string line;
    std::getline(table, line);  // header
    while (std::getline(table, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
      fields >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >> timeout >> inode;
      if (state != "0A") continue;  // TCP_LISTEN
      sockets.push_back({std::stoi(local.substr(local.find(':') + 1), nullptr, 16), inode});
    }
  }
  return sockets;
}

// Every process /proc lists now (one that exits while the list is read is left out).
std::vector<ProcStat> all_processes() {
  std::vector<ProcStat> out;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    if (const auto stat = read_proc_stat(static_cast<pid_t>(std::stoi(name)))) out.push_back(*stat);
  }
  return out;
}

}  // namespace

std::string sim_manager_path() {
  const char* from_env = std::getenv("RFBSIM_SIM_MANAGER");
#ifdef RFBSIM_SIM_MANAGER_DEFAULT
  return from_env != nullptr ? from_env : RFBSIM_SIM_MANAGER_DEFAULT;
#else
  return from_env != nullptr ? from_env : "sim_manager";
#endif
}

TempDir::TempDir(const std::string& prefix) {
  static std::atomic<int> counter{0};
  std::random_device random;
  path_ = std::filesystem::temp_directory_path() / (prefix + "-" + std::to_string(::getpid()) + "-" +
                                                    std::to_string(counter++) + "-" + std::to_string(random()));
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

std::vector<std::string> with_small_sessions(std::vector<std::string> flags) {
  const auto small = small_session_args();
  flags.insert(flags.end(), small.begin(), small.end());
  return flags;
}

std::vector<std::string> without_abuse_limits(std::vector<std::string> flags) {
  for (const char* flag : {"--rate-start-per-minute", "--rate-upgrade-per-minute", "--max-unspent-sessions-per-address"}) {
    flags.emplace_back(flag);
    flags.emplace_back("0");
  }
  return flags;
}

ManagerUnderTest::ManagerUnderTest(const std::filesystem::path& data_dir, const std::vector<std::string>& flags,
                                   ManagerOptions options)
    : data_dir_(data_dir), options_(std::move(options)) {
  std::vector<std::string> args = {"--port", "0", "--data-dir", data_dir.string()};
  args.insert(args.end(), flags.begin(), flags.end());
  process_ = std::make_unique<SimProcess>(options_.program, args, std::chrono::seconds(30), options_.log_file.string());
}

ManagerUnderTest::~ManagerUnderTest() {
  // A no-op when a test stopped it already; SimProcess's own destructor kills it if this times out.
  process_->stop(options_.stop_signal, options_.stop_timeout);
}

std::string ManagerUnderTest::ws_url(const std::string& token, bool tls) const {
  return std::string(tls ? "wss" : "ws") + "://127.0.0.1:" + std::to_string(port()) + "/s/" + token + "/ws";
}

std::string ManagerUnderTest::origin() const { return "http://127.0.0.1:" + std::to_string(port()); }

net::HttpResponse ManagerUnderTest::start(const std::string& query, bool tls) const {
  return net::http_get(port(), "/start?" + query, {}, tls);
}

net::HttpResponse ManagerUnderTest::get(const std::string& target,
                                        const std::vector<std::pair<std::string, std::string>>& headers,
                                        bool tls) const {
  return net::http_get(port(), target, headers, tls);
}

net::HttpResponse ManagerUnderTest::end_session(std::int64_t id, const std::string& admin_token) const {
  const std::string request = "POST /api/sessions/" + std::to_string(id) +
                              "/end HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + admin_token +
                              "\r\nX-Rfbsim-Admin: 1\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
  return net::http_request(port(), request);
}

std::string ManagerUnderTest::state_of(const std::string& token, bool tls) const {
  const net::HttpResponse response = get("/s/" + token + "/status", {}, tls);
  const std::string key = "\"state\":\"";
  const std::size_t at = response.body.find(key);
  if (response.status != 200 || at == std::string::npos) return "";
  const std::size_t start = at + key.size();
  return response.body.substr(start, response.body.find('"', start) - start);
}

bool ManagerUnderTest::wait_for_state(const std::string& token, const std::string& state,
                                      std::chrono::milliseconds timeout, bool tls) const {
  // The index is written off the manager's I/O thread, a moment after the page's status changes: wait for both,
  // so that a test reading the row next sees the state it waited for.
  return eventually(
      [&] {
        if (state_of(token, tls) != state) return false;
        try {
          const auto row = row_for_token(token);
          return row && row->state == state;
        } catch (const std::exception&) {
          return false;  // the index is not there yet
        }
      },
      timeout, options_.poll_interval);
}

std::vector<IndexRow> ManagerUnderTest::query_index(const std::optional<std::string>& token) const {
  sqlite3* db = nullptr;
  const std::string path = (data_dir_ / "sessions.db").string();
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    throw std::runtime_error("cannot open " + path);
  }
  // The manager writes while we read.
  sqlite3_busy_timeout(db, 5000);
  sqlite3_stmt* stmt = nullptr;
  const std::string sql =
      std::string("SELECT id, uid, token, scenario, params, seed, host_id, state, detail, exit_status, data_path, "
                  "pid, port, created_at, ready_at, ended_at, spent_at, data_incomplete FROM sessions") +
      (token ? " WHERE token = ?" : "") + " ORDER BY id";
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
    const std::string message = sqlite3_errmsg(db);
    sqlite3_close(db);
    throw std::runtime_error("index query failed: " + message);
  }
  if (token) sqlite3_bind_text(stmt, 1, token->c_str(), -1, SQLITE_TRANSIENT);
  // NULL reads as "".
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
    row.created_at = text(13);
    row.ready_at = text(14);
    row.spent_at = text(16);
    row.data_incomplete = text(17);
    row.ended_at = text(15);
    rows.push_back(row);
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return rows;
}

std::vector<IndexRow> ManagerUnderTest::index_rows() const { return query_index(std::nullopt); }

std::optional<IndexRow> ManagerUnderTest::row_for_token(const std::string& token) const {
  std::vector<IndexRow> rows = query_index(token);
  if (rows.empty()) return std::nullopt;
  return std::move(rows.front());
}

std::optional<IndexRow> ManagerUnderTest::wait_for_row(const std::string& token,
                                                       const std::function<bool(const IndexRow&)>& done,
                                                       std::chrono::milliseconds timeout) const {
  std::optional<IndexRow> row;
  const bool found = eventually(
      [&] {
        row = row_for_token(token);
        return row && done(*row);
      },
      timeout, options_.poll_interval);
  return found ? row : std::nullopt;
}

std::vector<pid_t> ManagerUnderTest::children() const {
  std::vector<pid_t> out;
  for (const ProcStat& stat : all_processes()) {
    if (stat.parent == pid() && stat.state != 'Z') out.push_back(stat.pid);
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

double ManagerUnderTest::metric(const std::string& name) const {
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

net::HttpResponse admin_post(const ManagerUnderTest& manager, const std::string& path, bool admin_header) {
  return net::http_request(manager.port(), "POST " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " +
                                               kAdminToken + "\r\n" + (admin_header ? "X-Rfbsim-Admin: 1\r\n" : "") +
                                               "Content-Length: 0\r\nConnection: close\r\n\r\n");
}

int free_loopback_port() {
  std::mt19937 random(static_cast<unsigned>(::getpid()) ^ static_cast<unsigned>(std::random_device{}()));
  std::uniform_int_distribution<int> pick(10000, 19999);
  for (int attempt = 0; attempt < 200; ++attempt) {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) throw std::runtime_error("free_loopback_port: socket failed");
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const int port = pick(random);
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    const bool bound = ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
    ::close(fd);
    if (bound) return port;
  }
  throw std::runtime_error("free_loopback_port: no free loopback port in 10000-19999");
}

bool process_exists(pid_t pid) {
  const auto stat = read_proc_stat(pid);
  return stat && stat->state != 'Z';
}

bool group_has_running_member(pid_t pgid) {
  const std::vector<ProcStat> processes = all_processes();
  return std::any_of(processes.begin(), processes.end(),
                     [pgid](const ProcStat& stat) { return stat.group == pgid && stat.state != 'Z'; });
}

std::vector<pid_t> listener_groups(int port) {
  // The sockets' inodes, then the processes holding a descriptor of one.
  std::vector<std::string> inodes;
  for (const ListeningSocket& socket : listening_sockets()) {
    if (socket.port == port) inodes.push_back("socket:[" + socket.inode + "]");
  }
  std::vector<pid_t> groups;
  if (inodes.empty()) return groups;
  for (const ProcStat& process : all_processes()) {
    std::error_code error;
    const std::filesystem::path fds = "/proc/" + std::to_string(process.pid) + "/fd";
    for (const auto& fd : std::filesystem::directory_iterator(fds, error)) {
      const std::string target = std::filesystem::read_symlink(fd.path(), error).string();
      if (std::find(inodes.begin(), inodes.end(), target) != inodes.end()) groups.push_back(process.group);
    }
  }
  return groups;
}

std::vector<int> listening_ports() {
  std::vector<int> ports;
  for (const ListeningSocket& socket : listening_sockets()) ports.push_back(socket.port);
  return ports;
}


}  // namespace rfbsim::test
