// SPDX-License-Identifier: GPL-2.0-or-later
// TrajectoryDiff: two trajectories.csv files, line by line.
#include "trajectory_diff.hpp"

#include <sstream>
#include <stdexcept>

#include "record/session_log.hpp"

namespace rfbsim::replay {

namespace {

constexpr const char* kEndOfFile = "(end of file)";

// The file's complete lines (session_log's rule: a torn last line is dropped). A file that cannot be read
// here, after the session was read once, is a failure of the run, not bad session data.
std::vector<std::string> complete_lines(const std::filesystem::path& file) {
  try {
    return sim::read_complete_lines(file);
  } catch (const sim::SessionLogError& e) {
    throw std::runtime_error(e.what());
  }
}

std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  return cells;
}

// The header's names of the cells that differ between two rows of the same shape.
std::vector<std::string> differing_columns(const std::string& header, const std::string& a, const std::string& b) {
  const auto names = cells_of(header);
  const auto x = cells_of(a);
  const auto y = cells_of(b);
  std::vector<std::string> columns;
  if (x.size() != y.size()) return columns;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (x[i] != y[i]) columns.push_back(i < names.size() ? names[i] : "column " + std::to_string(i + 1));
  }
  return columns;
}

}  // namespace

TrajectoryComparison compare_trajectories(const std::filesystem::path& recorded, const std::filesystem::path& replayed,
                                          bool recorded_may_end_early) {
  const std::vector<std::string> old_lines = complete_lines(recorded);
  const std::vector<std::string> new_lines = complete_lines(replayed);
  TrajectoryComparison result;
  const std::size_t common = std::min(old_lines.size(), new_lines.size());
  for (std::size_t i = 0; i < common; ++i) {
    if (old_lines[i] != new_lines[i]) {
      const std::string& header = new_lines.empty() ? old_lines[0] : new_lines[0];
      result.difference = TrajectoryDifference{i + 1, old_lines[i], new_lines[i],
                                               i == 0 ? std::vector<std::string>{} : differing_columns(header, old_lines[i], new_lines[i])};
      return result;
    }
    if (i > 0) ++result.rows;
  }
  // One file goes on where the other stopped.
  if (new_lines.size() > common && !recorded_may_end_early) {
    result.difference = TrajectoryDifference{common + 1, kEndOfFile, new_lines[common], {}};
  } else if (old_lines.size() > common) {
    result.difference = TrajectoryDifference{common + 1, old_lines[common], kEndOfFile, {}};
  }
  return result;
}

std::string describe(const TrajectoryDifference& difference) {
  std::string where = "trajectories.csv line " + std::to_string(difference.line);
  const std::string& row = difference.recorded != kEndOfFile ? difference.recorded : difference.replayed;
  const auto cells = cells_of(row);
  if (difference.line > 1 && cells.size() >= 4) {
    where += " (tick " + cells[0] + ", " + cells[2] + " " + cells[3];
    if (!difference.columns.empty()) {
      where += difference.columns.size() == 1 ? ", column " : ", columns ";
      for (std::size_t i = 0; i < difference.columns.size(); ++i) where += (i > 0 ? ", " : "") + difference.columns[i];
    }
    where += ")";
  }
  return where + ":\n  recorded: " + difference.recorded + "\n  replayed: " + difference.replayed;
}

}  // namespace rfbsim::replay
