// SPDX-License-Identifier: GPL-2.0-or-later
// Small helpers shared by the benchmarks: sample summaries, a plain-text table, command-line lists and
// a description of the machine. No timing policy here: benchmarks print numbers, they never pass or fail.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

namespace rfbsim::bench {

using Clock = std::chrono::steady_clock;

/// Milliseconds between two time points.
double ms_between(Clock::time_point from, Clock::time_point to);

/// Order statistics of a set of samples (linear interpolation between closest ranks).
struct Summary {
  std::size_t n = 0;  ///< samples
  double p50 = 0.0;
  double p90 = 0.0;
  double p99 = 0.0;
  double mean = 0.0;
  double max = 0.0;
};

/// Summarises `samples` (any order); all zero when empty.
Summary summarize(std::vector<double> samples);

/// Formats "p50 / p90" with `decimals` digits after the point; "-" when there are no samples.
std::string p50_p90(const Summary& s, int decimals = 2);

/// Formats one number with `decimals` digits after the point.
std::string fixed(double value, int decimals = 2);

/// A text table printed as GitHub-flavoured markdown with aligned columns.
class Table {
 public:
  /// Column headings; numeric columns are right-aligned by default (every column but the first two).
  explicit Table(std::vector<std::string> headings, std::size_t left_aligned_columns = 2);
  /// Appends a row with one cell per heading.
  void add_row(std::vector<std::string> cells);
  /// Prints the table to stdout.
  void print() const;

 private:
  std::vector<std::string> headings_;
  std::vector<std::vector<std::string>> rows_;
  std::size_t left_aligned_;
};

/// A frame size parsed from "WIDTHxHEIGHT".
struct Size {
  int width = 0;
  int height = 0;
  [[nodiscard]] std::string text() const;
};

/// Parses a comma-separated list of sizes ("1280x720,640x480"). Throws std::invalid_argument naming the bad item.
std::vector<Size> parse_sizes(const std::string& text);
/// Parses a comma-separated list of integers. Throws std::invalid_argument naming the bad item.
std::vector<int> parse_ints(const std::string& text);
/// Parses one integer in [low, high]; `what` names the option in the error.
int parse_int(const std::string& text, int low, int high, const std::string& what);
/// Splits a comma-separated list into its items.
std::vector<std::string> split_list(const std::string& text);

/// The CPU model and the number of online cores, e.g. "Intel(R) Xeon(R) ... x 2 cores".
std::string cpu_description();
/// The one-minute load average (from /proc/loadavg): other work on the machine skews every timing.
std::string load_average();

/// Points this process's stderr at a file (appending) while the object lives, so that a child started
/// meanwhile writes its chatter there instead of between a table's lines. Throws std::runtime_error
/// when the file cannot be opened.
class StderrToFile {
 public:
  explicit StderrToFile(const std::string& path);
  ~StderrToFile();
  StderrToFile(const StderrToFile&) = delete;
  StderrToFile& operator=(const StderrToFile&) = delete;

 private:
  int saved_;  ///< a duplicate of the original stderr, put back on destruction
};

/// The renderer sim_rfb announced last in a log file ("[sim_rfb] rendering with ..."); "unknown" if none.
std::string renderer_in_log(const std::string& log_path);

}  // namespace rfbsim::bench
