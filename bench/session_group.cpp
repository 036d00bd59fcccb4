// SPDX-License-Identifier: GPL-2.0-or-later
// A session's process group from /proc; see session_group.hpp.
#include "session_group.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace rfbsim::bench {

namespace {

// The first line of a /proc file ("" when it cannot be read: the process has gone).
std::string first_line(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

// Reads process `pid` into `member` if its group is `pgid`. /proc/PID/stat holds the group in field 5 and
// utime, stime in 14 and 15 (clock ticks); the command name (field 2) may hold spaces and parentheses, so the
// fields are counted from the last ')'.
bool read_member(pid_t pid, pid_t pgid, GroupMember& member) {
  const std::filesystem::path proc = "/proc/" + std::to_string(pid);
  const std::string stat = first_line(proc / "stat");
  const std::size_t name_end = stat.rfind(')');
  const std::size_t name_start = stat.find('(');
  if (name_end == std::string::npos || name_start == std::string::npos || name_end + 2 > stat.size()) return false;
  std::istringstream fields(stat.substr(name_end + 2));
  std::string field;
  long group = -1;
  double ticks = 0.0;
  for (int index = 3; index <= 15 && fields >> field; ++index) {
    if (index == 3 && field == "Z") return false;  // a zombie runs nothing any more
    if (index == 5) group = std::strtol(field.c_str(), nullptr, 10);
    if (index >= 14) ticks += std::strtod(field.c_str(), nullptr);
  }
  if (group != pgid) return false;
  member.pid = pid;
  member.name = stat.substr(name_start + 1, name_end - name_start - 1);
  member.cpu_s = ticks / static_cast<double>(::sysconf(_SC_CLK_TCK));

  // VmRSS from status ("VmRSS:	  12345 kB").
  std::ifstream status(proc / "status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) member.rss_mib = std::strtod(line.c_str() + 6, nullptr) / 1024.0;
  }
  return true;
}

}  // namespace

std::vector<GroupMember> group_members(pid_t pgid) {
  std::vector<GroupMember> members;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator("/proc", ec); !ec && it != std::filesystem::directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || !std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; })) continue;
    GroupMember member;
    if (read_member(static_cast<pid_t>(std::strtol(name.c_str(), nullptr, 10)), pgid, member)) {
      members.push_back(std::move(member));
    }
  }
  std::sort(members.begin(), members.end(), [](const GroupMember& a, const GroupMember& b) { return a.pid < b.pid; });
  return members;
}

double group_cpu_s(const std::vector<GroupMember>& members) {
  double total = 0.0;
  for (const GroupMember& m : members) total += m.cpu_s;
  return total;
}

double group_rss_mib(const std::vector<GroupMember>& members) {
  double total = 0.0;
  for (const GroupMember& m : members) total += m.rss_mib;
  return total;
}

double group_cpu_between(const std::vector<GroupMember>& before, const std::vector<GroupMember>& after) {
  double total = 0.0;
  for (const GroupMember& later : after) {
    const auto earlier =
        std::find_if(before.begin(), before.end(), [&](const GroupMember& m) { return m.pid == later.pid; });
    total += later.cpu_s - (earlier == before.end() ? 0.0 : earlier->cpu_s);
  }
  return total;
}

std::string group_breakdown(const std::vector<GroupMember>& before, const std::vector<GroupMember>& after,
                            double wall_s) {
  std::string text;
  for (const GroupMember& m : after) {
    const double cores = group_cpu_between(before, {m}) / wall_s;
    char line[128];
    std::snprintf(line, sizeof line, "%s %.2f cores, %.0f MiB", m.name.c_str(), cores, m.rss_mib);
    text += (text.empty() ? "" : " + ") + std::string(line);
  }
  return text;
}

}  // namespace rfbsim::bench
