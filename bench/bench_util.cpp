// SPDX-License-Identifier: GPL-2.0-or-later
// Benchmark helpers: summaries, tables, list parsing, machine description.
#include "bench_util.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <stdexcept>

namespace rfbsim::bench {

double ms_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

namespace {

// The q-quantile (0..1) of sorted samples, interpolating linearly between the closest ranks.
double quantile(const std::vector<double>& sorted, double q) {
  const double position = q * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(position);
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  const double fraction = position - static_cast<double>(below);
  return sorted[below] + (sorted[above] - sorted[below]) * fraction;
}

}  // namespace

Summary summarize(std::vector<double> samples) {
  Summary s;
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  s.n = samples.size();
  s.p50 = quantile(samples, 0.50);
  s.p90 = quantile(samples, 0.90);
  s.p99 = quantile(samples, 0.99);
  s.mean = std::accumulate(samples.begin(), samples.end(), 0.0) / static_cast<double>(samples.size());
  s.max = samples.back();
  return s;
}

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string p50_p90(const Summary& s, int decimals) {
  if (s.n == 0) return "-";
  return fixed(s.p50, decimals) + " / " + fixed(s.p90, decimals);
}

Table::Table(std::vector<std::string> headings, std::size_t left_aligned_columns)
    : headings_(std::move(headings)), left_aligned_(left_aligned_columns) {}

void Table::add_row(std::vector<std::string> cells) {
  cells.resize(headings_.size());
  rows_.push_back(std::move(cells));
}

void Table::print() const {
  // Column widths: the widest of the heading and every cell.
  std::vector<std::size_t> widths(headings_.size());
  for (std::size_t c = 0; c < headings_.size(); ++c) {
    widths[c] = std::max<std::size_t>(3, headings_[c].size());  // room for a markdown rule such as "--:"
    for (const auto& row : rows_) widths[c] = std::max(widths[c], row[c].size());
  }
  const auto print_row = [&](const std::vector<std::string>& cells) {
    std::string line = "|";
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string pad(widths[c] - cells[c].size(), ' ');
      line += " " + (c < left_aligned_ ? cells[c] + pad : pad + cells[c]) + " |";
    }
    std::puts(line.c_str());
  };
  print_row(headings_);
  std::string rule = "|";
  for (std::size_t c = 0; c < widths.size(); ++c) {
    rule += c < left_aligned_ ? " " + std::string(widths[c], '-') + " |" : " " + std::string(widths[c] - 1, '-') + ": |";
  }
  std::puts(rule.c_str());
  for (const auto& row : rows_) print_row(row);
  std::fflush(stdout);
}

std::string Size::text() const { return std::to_string(width) + "x" + std::to_string(height); }

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    items.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return items;
}

int parse_int(const std::string& text, int low, int high, const std::string& what) {
  std::size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || value < low || value > high) {
    throw std::invalid_argument(what + ": '" + text + "' is not an integer in " + std::to_string(low) + ".." +
                                std::to_string(high));
  }
  return value;
}

std::vector<Size> parse_sizes(const std::string& text) {
  std::vector<Size> sizes;
  for (const std::string& item : split_list(text)) {
    const std::size_t x = item.find('x');
    if (x == std::string::npos) throw std::invalid_argument("size '" + item + "' is not WIDTHxHEIGHT");
    sizes.push_back({parse_int(item.substr(0, x), 16, 8192, "width"), parse_int(item.substr(x + 1), 16, 8192, "height")});
  }
  return sizes;
}

std::vector<int> parse_ints(const std::string& text) {
  std::vector<int> values;
  for (const std::string& item : split_list(text)) values.push_back(parse_int(item, 1, 1000000, "list item"));
  return values;
}

std::string cpu_description() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  std::string model = "unknown CPU";
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      const std::size_t colon = line.find(':');
      if (colon != std::string::npos) model = line.substr(colon + 2);
      break;
    }
  }
  return model + " x " + std::to_string(::sysconf(_SC_NPROCESSORS_ONLN)) + " cores";
}

std::string load_average() {
  std::ifstream loadavg("/proc/loadavg");
  std::string one_minute = "?";
  loadavg >> one_minute;
  return one_minute;
}

StderrToFile::StderrToFile(const std::string& path) : saved_(::dup(STDERR_FILENO)) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) {
    ::close(saved_);
    throw std::runtime_error("cannot open the log " + path);
  }
  ::dup2(fd, STDERR_FILENO);
  ::close(fd);
}

StderrToFile::~StderrToFile() {
  ::dup2(saved_, STDERR_FILENO);
  ::close(saved_);
}

std::string renderer_in_log(const std::string& log_path) {
  std::ifstream log(log_path);
  const std::string marker = "rendering with ";
  std::string line;
  std::string found = "unknown";
  while (std::getline(log, line)) {
    const std::size_t at = line.find(marker);
    if (at != std::string::npos) found = line.substr(at + marker.size());
  }
  return found;
}

}  // namespace rfbsim::bench
