// SPDX-License-Identifier: GPL-2.0-or-later
// The 8 neighbours of a costmap cell, as column and row steps, shared by the global planner's search and the
// local planner's distance grid so that both walk the grid in the same order.
#pragma once

namespace rfbsim::sim {

/// Column steps of the 8 neighbours: the 4 straight ones first (indexes 0..3), then the diagonals (4..7).
inline constexpr int kNeighbourDc[8] = {1, -1, 0, 0, 1, -1, 1, -1};
/// Row steps of the same 8 neighbours, index for index with kNeighbourDc.
inline constexpr int kNeighbourDr[8] = {0, 0, 1, -1, 1, 1, -1, -1};

}  // namespace rfbsim::sim
