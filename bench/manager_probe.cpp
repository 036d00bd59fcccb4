// SPDX-License-Identifier: GPL-2.0-or-later
// /proc readings of a process; see manager_probe.hpp.
#include "manager_probe.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rfbsim::bench {

ProcessSample sample_process(pid_t pid) {
  const std::filesystem::path proc = "/proc/" + std::to_string(pid);
  ProcessSample sample;

  // VmRSS from status ("VmRSS:	  12345 kB").
  std::ifstream status(proc / "status");
  if (!status) throw std::runtime_error("cannot read " + (proc / "status").string());
  bool has_memory = false;  // a zombie (exited, not yet reaped) has no VmRSS line
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) {
      sample.rss_mib = std::stod(line.substr(6)) / 1024.0;
      has_memory = true;
    }
  }
  if (!has_memory) throw std::runtime_error("process " + std::to_string(pid) + " has exited");

  // Descriptors: one entry each in fd/.
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(proc / "fd", ec); !ec && it != std::filesystem::directory_iterator();
       it.increment(ec)) {
    ++sample.descriptors;
  }
  if (ec) throw std::runtime_error("cannot list " + (proc / "fd").string() + ": " + ec.message());

  // utime and stime are fields 14 and 15 of stat; the command name (field 2) may hold spaces, so count from
  // the last ')'.
  std::ifstream stat_file(proc / "stat");
  std::string stat;
  std::getline(stat_file, stat);  // one line
  const std::size_t after_name = stat.rfind(')');
  if (after_name == std::string::npos) throw std::runtime_error("cannot parse " + (proc / "stat").string());
  std::istringstream fields(stat.substr(after_name + 2));
  std::string field;
  double ticks = 0.0;
  for (int index = 3; index <= 15 && fields >> field; ++index) {
    if (index >= 14) ticks += std::stod(field);
  }
  sample.cpu_s = ticks / static_cast<double>(::sysconf(_SC_CLK_TCK));
  return sample;
}

long raise_descriptor_limit(long wanted) {
  rlimit limit{};
  if (::getrlimit(RLIMIT_NOFILE, &limit) != 0) return -1;
  const rlim_t target = std::min<rlim_t>(static_cast<rlim_t>(wanted), limit.rlim_max);
  if (limit.rlim_cur < target) {
    limit.rlim_cur = target;
    ::setrlimit(RLIMIT_NOFILE, &limit);
    ::getrlimit(RLIMIT_NOFILE, &limit);
  }
  return static_cast<long>(limit.rlim_cur);
}

}  // namespace rfbsim::bench
