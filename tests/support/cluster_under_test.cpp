// SPDX-License-Identifier: GPL-2.0-or-later
// ClusterUnderTest: the script as a child in its own process group, its printed lines parsed, and HTTP to
// HAProxy, the hosts and HAProxy's stats page.
#include "cluster_under_test.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "file_text.hpp"
#include "manager_process.hpp"

namespace rfbsim::test {

namespace {

using namespace std::chrono_literals;

// Waits up to `timeout` for child `pid`; true when it was reaped.
bool reap_within(pid_t pid, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t got = ::waitpid(pid, &status, WNOHANG);
    if (got == pid || (got < 0 && errno == ECHILD)) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(20ms);
  }
}

}  // namespace

std::string minimal_sessions_yaml(int unseen_s) {
  // Tests start sessions no browser opens for a while: keep them until the test ends them.
  const std::string unseen = std::to_string(unseen_s);
  return std::string("session_kind: rfb\nsession_command: ") + RFBSIM_MINIMAL +
         "\nsession_args: [\"{port}\"]\nscenarios: [demo]\nfirst_connect_timeout_s: " + unseen +
         "\nidle_timeout_s: " + unseen + "\nmax_duration_s: " + std::to_string(std::max(unseen_s, 300)) +
         "\nstop_grace_s: 1\n";
}

std::string sim_rfb_sessions_yaml() {
  return std::string("session_command: ") + RFBSIM_SIM_RFB +
         "\nsession_args: [--width, \"320\", --height, \"240\", --fps, \"15\"]\nscenarios: [lab]\n"
         "first_connect_timeout_s: 120\nidle_timeout_s: 120\nstop_grace_s: 2\n";
}

int free_cluster_base_port(int hosts) {
  std::mt19937 random(static_cast<unsigned>(::getpid()) ^ static_cast<unsigned>(std::random_device{}()));
  // A cluster uses base..base+303: bases 400 apart never overlap, and 20000..31600 stays below the
  // ephemeral ports (32768-60999) that clients and pick_free_port draw from.
  std::uniform_int_distribution<int> pick(50, 79);
  for (int attempt = 0; attempt < 50; ++attempt) {
    const int base = pick(random) * 400;
    std::vector<int> wanted{base, base + 300};
    for (int i = 1; i <= hosts; ++i) {
      for (int offset : {0, 100, 200}) wanted.push_back(base + offset + i);
    }
    const std::vector<int> busy = listening_ports();
    const bool free = std::none_of(wanted.begin(), wanted.end(), [&](int port) {
      return std::find(busy.begin(), busy.end(), port) != busy.end();
    });
    if (free) return base;
  }
  throw std::runtime_error("no free port range for a cluster");
}

std::pair<std::string, std::string> session_of_location(const std::string& location) {
  static const std::regex pattern(R"(^/([a-z0-9-]+)/s/([A-Za-z0-9_-]+)/$)");
  std::smatch match;
  if (!std::regex_match(location, match, pattern)) return {"", ""};
  return {match[1], match[2]};
}

namespace {

// The script exited before `cluster ready`: usually a port seen free was taken before a host bound it (a
// client's ephemeral port, another test's cluster), so the constructor tries again on another base.
struct ScriptExitedEarly : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace

ClusterUnderTest::ClusterUnderTest(const ClusterOptions& options) {
  constexpr int kTries = 3;
  for (int attempt = 1;; ++attempt) {
    try {
      launch(options);
      return;
    } catch (const ScriptExitedEarly& error) {
      if (attempt == kTries) throw;
      std::fprintf(stderr, "cluster: try %d of %d failed, another base port next:\n%s\n", attempt, kTries, error.what());
      std::error_code ignored;
      std::filesystem::remove_all(run_dir_, ignored);
      hosts_.clear();
      haproxy_pid_ = -1;
    }
  }
}

void ClusterUnderTest::launch(const ClusterOptions& options) {
  port_ = free_cluster_base_port(options.hosts);
  stats_port_ = port_ + 300;
  run_dir_ = std::filesystem::temp_directory_path() /
             ("rfbsim-cluster-" + std::to_string(::getpid()) + "-" + std::to_string(port_));
  std::filesystem::remove_all(run_dir_);
  std::filesystem::create_directories(run_dir_);
  std::vector<std::string> args{RFBSIM_CLUSTER_SCRIPT,   "--hosts",     std::to_string(options.hosts),
                                "--port",                std::to_string(port_),
                                "--max-sessions",        std::to_string(options.max_sessions),
                                "--build-dir",           RFBSIM_BUILD_DIR,
                                "--run-dir",             run_dir_.string()};
  if (options.rate_limit) args.emplace_back("--rate-limit");
  if (!options.config_yaml.empty()) {
    std::ofstream(run_dir_ / "base.yaml") << options.config_yaml;
    args.emplace_back("--config");
    args.push_back((run_dir_ / "base.yaml").string());
  }

  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  script_pid_ = ::fork();
  if (script_pid_ < 0) throw std::runtime_error("fork failed");
  if (script_pid_ == 0) {
    // Its own process group, so that the teardown can reach everything it started; SIGTERM (which the script
    // turns into stopping everything) if this test dies first.
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    ::dup2(pipe_fds[1], STDOUT_FILENO);
    ::execv(argv[0], argv.data());
    _exit(127);
  }
  ::setpgid(script_pid_, script_pid_);  // also here: whichever runs first
  ::close(pipe_fds[1]);
  output_fd_ = pipe_fds[0];

  // Its lines, up to `cluster ready: URL`.
  std::string output;
  const auto deadline = std::chrono::steady_clock::now() + 90s;
  while (output.find("cluster ready: ") == std::string::npos ||
         output.find('\n', output.find("cluster ready: ")) == std::string::npos) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{output_fd_, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) {
      stop();
      throw std::runtime_error("run-cluster-demo.sh was not ready within 90 s; it printed:\n" + output);
    }
    char buffer[4096];
    const ssize_t n = ::read(output_fd_, buffer, sizeof buffer);
    if (n <= 0) {
      stop();
      throw ScriptExitedEarly("run-cluster-demo.sh exited before it was ready; it printed:\n" + output);
    }
    output.append(buffer, static_cast<std::size_t>(n));
  }
  static const std::regex host_line(R"(host (h\d+) pid (\d+) port (\d+) data (\S+))");
  static const std::regex haproxy_line(R"(haproxy pid (\d+))");
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    std::smatch match;
    if (std::regex_search(line, match, host_line)) {
      hosts_.push_back({match[1], static_cast<pid_t>(std::stol(match[2])), std::stoi(match[3]), match[4].str()});
    } else if (std::regex_search(line, match, haproxy_line)) {
      haproxy_pid_ = static_cast<pid_t>(std::stol(match[1]));
    }
  }
  admin_token_ = rfbsim::test::file_text(run_dir_ / "admin-token");
  if (static_cast<int>(hosts_.size()) != options.hosts || haproxy_pid_ <= 0 || admin_token_.empty()) {
    stop();
    throw std::runtime_error("run-cluster-demo.sh printed unexpected lines:\n" + output);
  }
}

ClusterUnderTest::~ClusterUnderTest() {
  stop();
  // RFBSIM_KEEP_CLUSTER=1 keeps the run dir (logs, configs, data) for a look after a failure.
  if (std::getenv("RFBSIM_KEEP_CLUSTER") != nullptr) return;
  std::error_code ignored;
  std::filesystem::remove_all(run_dir_, ignored);
}

void ClusterUnderTest::stop() {
  if (script_pid_ > 0) {
    ::kill(script_pid_, SIGTERM);
    if (!reap_within(script_pid_, 40s)) {
      ::kill(-script_pid_, SIGKILL);
      reap_within(script_pid_, 5s);
    }
    // Whatever the script left in its group (nothing, when it works) goes too.
    ::kill(-script_pid_, SIGKILL);
    script_pid_ = -1;
  }
  for (const pid_t child : own_children_) {
    ::kill(child, SIGKILL);  // stopped by the script already, unless it failed
    reap_within(child, 5s);
  }
  own_children_.clear();
  if (output_fd_ >= 0) ::close(output_fd_);
  output_fd_ = -1;
}

const ClusterHost& ClusterUnderTest::host(const std::string& id) const {
  for (const ClusterHost& host : hosts_) {
    if (host.id == id) return host;
  }
  throw std::invalid_argument("no host " + id);
}

net::HttpResponse ClusterUnderTest::get(const std::string& target,
                                        const std::vector<std::pair<std::string, std::string>>& headers) const {
  return net::http_get(port_, target, headers);
}

net::HttpResponse ClusterUnderTest::get_direct(const std::string& id, const std::string& target) const {
  return net::http_get(host(id).port, target);
}

StartResult ClusterUnderTest::start(const std::string& query, const std::string& path, int via_port) const {
  StartResult result;
  std::string target = path + "?" + query;
  for (int hop = 0; hop < 4; ++hop) {
    result.response = net::http_get(via_port > 0 ? via_port : port_, target);
    result.statuses.push_back(result.response.status);
    if (hop == 0) {
      const auto served = result.response.headers.find("x-rfbsim-host");
      if (served != result.response.headers.end()) result.first_host = served->second;
    }
    const auto location = result.response.headers.find("location");
    if (result.response.status == 303 && location != result.response.headers.end() && hop < 3) {
      target = location->second;  // /<owner>/start?<query>: the registry named another host
      continue;
    }
    if (result.response.status == 302 && location != result.response.headers.end()) {
      std::tie(result.host, result.token) = session_of_location(location->second);
    }
    break;
  }
  return result;
}

std::string ClusterUnderTest::state_of(const std::string& host, const std::string& token) const {
  const net::HttpResponse response = get("/" + host + "/s/" + token + "/status");
  const auto json = nlohmann::json::parse(response.body, nullptr, false);
  if (json.is_discarded() || !json.is_object() || !json.contains("state") || !json["state"].is_string()) return "";
  return json["state"];
}

net::HttpResponse ClusterUnderTest::admin_post(const std::string& id, const std::string& path) const {
  const std::string request = "POST /" + id + path + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port_) +
                              "\r\nAuthorization: Bearer " + admin_token_ +
                              "\r\nX-Rfbsim-Admin: 1\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
  return net::http_request(port_, request);
}

bool ClusterUnderTest::end_session(const std::string& id, const std::string& token) const {
  const net::HttpResponse sessions = get("/" + id + "/api/sessions", {{"Authorization", "Bearer " + admin_token_}});
  const auto json = nlohmann::json::parse(sessions.body, nullptr, false);
  if (json.is_discarded() || !json.contains("live")) return false;
  for (const auto& session : json["live"]) {
    if (session.value("token", "") != token) continue;
    return admin_post(id, "/api/sessions/" + std::to_string(session["id"].get<long long>()) + "/end").status == 200;
  }
  return false;
}

std::string ClusterUnderTest::server_status(const std::string& backend, const std::string& server) const {
  // HAProxy's CSV: pxname,svname,...; the "status" column is named in the header line.
  const net::HttpResponse csv = net::http_get(stats_port_, "/stats;csv");
  std::istringstream lines(csv.body);
  std::string header;
  std::getline(lines, header);
  std::size_t status_column = 0;
  {
    std::istringstream names(header.substr(header.rfind('#', 0) == 0 ? 2 : 0));
    std::string name;
    for (std::size_t i = 0; std::getline(names, name, ','); ++i) {
      if (name == "status") status_column = i;
    }
  }
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> fields;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) fields.push_back(cell);
    if (fields.size() > status_column && fields[0] == backend && fields[1] == server) return fields[status_column];
  }
  return "";
}

bool ClusterUnderTest::wait_server_status(const std::string& backend, const std::string& server,
                                          const std::string& prefix, std::chrono::milliseconds timeout) const {
  return eventually([&] { return server_status(backend, server).rfind(prefix, 0) == 0; }, timeout, 100ms);
}

void ClusterUnderTest::signal_host(const std::string& id, int signal) {
  const pid_t pid = host(id).pid;
  ::kill(pid, signal);
  const auto own = std::find(own_children_.begin(), own_children_.end(), pid);
  if (own != own_children_.end()) {
    reap_within(pid, 10s);
    own_children_.erase(own);
  }
}

void ClusterUnderTest::restart_host(const std::string& id) {
  // The script's own argv for this host, NUL-separated.
  const std::string saved = rfbsim::test::file_text(run_dir_ / (id + ".argv"));
  std::vector<std::string> args;
  for (std::size_t start = 0; start < saved.size();) {
    const std::size_t end = saved.find('\0', start);
    args.push_back(saved.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  if (args.empty()) throw std::runtime_error("no argv saved for " + id);
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const std::string log = (run_dir_ / (id + ".log")).string();
  const std::string token_variable = "RFBSIM_ADMIN_TOKEN=" + admin_token_;
  // The address key the script gave every host: the study's own when set, else the run dir's.
  const char* study_key = std::getenv("RFBSIM_ADDRESS_KEY");
  const std::string key_variable =
      "RFBSIM_ADDRESS_KEY=" + (study_key != nullptr && *study_key != '\0' ? std::string(study_key)
                                                                          : rfbsim::test::file_text(run_dir_ / "address-key"));
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    ::setpgid(0, script_pid_);  // in the cluster's group, so that its teardown reaches it
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    const int out = ::open(log.c_str(), O_WRONLY | O_APPEND | O_CREAT, 0644);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(out, STDERR_FILENO);
    ::putenv(const_cast<char*>(token_variable.c_str()));
    ::putenv(const_cast<char*>(key_variable.c_str()));
    ::execv(argv[0], argv.data());
    _exit(127);
  }
  own_children_.push_back(pid);
  for (ClusterHost& host : hosts_) {
    if (host.id == id) host.pid = pid;
  }
  std::ofstream(run_dir_ / (id + ".pid")) << pid << "\n";
  const int port = host(id).port;
  if (!eventually([&] { return net::http_get(port, "/healthz", {}, false, 1s).status > 0; }, 30s, 100ms)) {
    throw std::runtime_error(id + " did not come back; its log:\n" + rfbsim::test::file_text(log));
  }
}

void ClusterUnderTest::reload_haproxy() {
  // The master logs "Loading success." once per worker it forked; a new one proves the reload happened (a
  // failed reload leaves the old worker running, which would pass every later check just the same).
  const auto loads = [&] {
    const std::string log = rfbsim::test::file_text(run_dir_ / "haproxy.log");
    std::size_t count = 0;
    for (auto at = log.find("Loading success."); at != std::string::npos; at = log.find("Loading success.", at + 1)) {
      ++count;
    }
    return count;
  };
  const std::size_t before = loads();
  ::kill(haproxy_pid_, SIGUSR2);
  if (!eventually([&] { return loads() > before; }, 10s, 100ms)) {
    throw std::runtime_error("HAProxy did not reload; its log:\n" + rfbsim::test::file_text(run_dir_ / "haproxy.log"));
  }
}

}  // namespace rfbsim::test
