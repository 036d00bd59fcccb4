// SPDX-License-Identifier: GPL-2.0-or-later
#include "manager_takeovers.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "bench_util.hpp"
#include "manager_probe.hpp"
#include "source_address.hpp"

namespace rfbsim::bench {

namespace {

using Clock = std::chrono::steady_clock;

// Sends a WebSocket upgrade for `target` and reads the answer's status line; the status, or -1.
int upgrade(int fd, const std::string& target, int port, const std::string& origin) {
  const std::string request = test::upgrade_request(target, port, origin);
  if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) return -1;
  std::string head;
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (head.find("\r\n") == std::string::npos && Clock::now() < deadline) {
    pollfd pfd{fd, POLLIN, 0};
    if (::poll(&pfd, 1, 100) <= 0) continue;
    char byte = 0;
    if (::recv(fd, &byte, 1, 0) != 1) break;
    head += byte;
  }
  int status = -1;
  if (std::sscanf(head.c_str(), "HTTP/1.1 %d", &status) != 1) return -1;
  return status;
}

std::uintmax_t file_size(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  return ec ? 0 : size;
}

int lines_about_takeovers(const std::string& path, std::uintmax_t from) {
  std::ifstream in(path);
  in.seekg(static_cast<std::streamoff>(from));
  int count = 0;
  for (std::string line; std::getline(in, line);) {
    count += line.find("took over") != std::string::npos || line.find("(takeover)") != std::string::npos ? 1 : 0;
  }
  return count;
}

}  // namespace

TakeoverStormResult run_takeover_storm(const ManagerRun& run, const std::string& label,
                                       const TakeoverStormOptions& options) {
  TakeoverStormResult result;
  result.label = label;
  const test::TempDir data("rfbsim-bench-takeovers");
  test::ManagerUnderTest manager = start_manager(run, data.path(), {"--width", "320", "--height", "240", "--fps", "15"}, 2);
  const std::string token = start_session(manager, "storm-owner", run.scenario);
  if (!manager.wait_for_state(token, "running", std::chrono::seconds(60))) {
    throw std::runtime_error("the storm's session did not start");
  }
  const std::string target = "/s/" + token + "/ws";
  const ProcessSample before = sample_process(manager.pid());
  const std::uintmax_t log_before = file_size(run.log);
  result.rss_before_mib = before.rss_mib;

  // Each upgrade is kept open and never read again; every one is held to the end, so none is gone before the
  // next takes over.
  std::vector<int> held;
  const auto start = Clock::now();
  const auto spacing = std::chrono::duration<double>(options.seconds) / std::max(options.upgrades, 1);
  for (int i = 0; i < options.upgrades; ++i) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(spacing * i));
    const std::string source = "127.0.1." + std::to_string(10 + i % options.addresses);
    const int fd = test::connect_from(source, manager.port());
    const int status = fd < 0 ? -1 : upgrade(fd, target, manager.port(), manager.origin());
    if (status == 101) {
      ++result.switched;
    } else if (status == 429) {
      ++result.rate_limited;
    } else {
      ++result.other;
    }
    if (fd >= 0) held.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));  // what the last ones cause is written
  const ProcessSample after = sample_process(manager.pid());
  result.cpu_s = after.cpu_s - before.cpu_s;
  result.rss_after_mib = after.rss_mib;
  result.takeovers = manager.metric("rfbsim_takeovers_total");
  result.log_kib = static_cast<double>(file_size(run.log) - log_before) / 1024.0;
  result.takeover_lines = lines_about_takeovers(run.log, log_before);
  for (const int fd : held) ::close(fd);
  return result;
}

void print_takeover_storm(const std::vector<TakeoverStormResult>& results, const TakeoverStormOptions& options) {
  std::printf("Takeover storm: %d WebSocket upgrades to one's own session from %d addresses over %d s, each left "
              "open and unread (default abuse limits)\n\n",
              options.upgrades, options.addresses, options.seconds);
  Table table({"manager", "101 / 429 / other", "takeovers", "log growth KiB", "takeover lines", "manager CPU s",
               "RSS before -> after MiB"});
  for (const TakeoverStormResult& r : results) {
    table.add_row({r.label,
                   std::to_string(r.switched) + " / " + std::to_string(r.rate_limited) + " / " + std::to_string(r.other),
                   fixed(r.takeovers, 0), fixed(r.log_kib, 1), std::to_string(r.takeover_lines), fixed(r.cpu_s, 2),
                   fixed(r.rss_before_mib, 1) + " -> " + fixed(r.rss_after_mib, 1)});
  }
  table.print();
  std::printf("\n");
}

}  // namespace rfbsim::bench
