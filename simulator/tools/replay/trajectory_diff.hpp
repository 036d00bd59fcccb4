// SPDX-License-Identifier: GPL-2.0-or-later
// TrajectoryDiff: a recorded trajectories.csv against a replay's, line by line as text. Both are written by
// the same code from the same numbers, so an exact replay gives the very same bytes; the first line that
// differs is where the replay departed from the log. Pure file reading, no simulation.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::replay {

/// The first line that differs. A missing line reads "(end of file)".
struct TrajectoryDifference {
  std::size_t line = 0;  ///< 1-based line number in trajectories.csv (1 = the header)
  std::string recorded;
  std::string replayed;
  std::vector<std::string> columns;  ///< the columns whose cells differ (tick, x, yaw, ...); empty if a line is missing
};

/// What the comparison found.
struct TrajectoryComparison {
  std::size_t rows = 0;  ///< data rows that matched (the header not counted)
  std::optional<TrajectoryDifference> difference;
};

/// Compares the recorded file with the replayed one. A torn last recorded line (no newline: a write cut
/// short by a kill) is left out. `recorded_may_end_early`: after a crash the log may stop before the
/// replay does; the lines it has must match, and the replay's extra lines are not a difference.
/// Throws std::runtime_error naming a file that cannot be read.
TrajectoryComparison compare_trajectories(const std::filesystem::path& recorded, const std::filesystem::path& replayed,
                                          bool recorded_may_end_early);

/// "trajectories.csv line 1234 (tick 600, avatar 0, columns x, vx):\n  recorded: ...\n  replayed: ...".
std::string describe(const TrajectoryDifference& difference);

}  // namespace rfbsim::replay
