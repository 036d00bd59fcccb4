// SPDX-License-Identifier: GPL-2.0-or-later
// Path shortcuts: straightening an 8-connected grid path into a few straight legs without making it any
// costlier or bringing it nearer to obstacles than the search's own path.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "robot/costmap/costmap_grid.hpp"

namespace rfbsim::sim {

/// Cost of the straight segment between the centres of cells `a` and `b`: the length (in cell lengths) it
/// runs through each cell times that cell's step cost. Sets `max_cost` to the highest costmap cost among
/// the cells crossed, counting both cells beside any grid corner it passes exactly through; returns +inf if
/// any of those cells is off the grid or has an infinite step cost (`step_cost` is indexed by costmap cost).
double segment_cost(const CostmapGrid& grid, Cell a, Cell b, const std::array<double, 256>& step_cost,
                    int& max_cost);

/// Indices into `cells` (a connected grid path, start first) of the corners of a straightened path. From
/// each kept cell the next kept one is a later path cell whose straight segment (1) crosses only passable
/// cells, (2) crosses no cell with a higher costmap cost than the costliest path cell it replaces, and
/// (3) costs at most what the grid path costs over that stretch (`g`: the search's cost to reach each path
/// cell). So the straightened path never raises the max cost nor the cost of the path. The first and last
/// cells are always kept; a stretch no segment may replace keeps every cell.
std::vector<std::size_t> shortcut_corners(const CostmapGrid& grid, const std::vector<Cell>& cells,
                                          const std::vector<double>& g, const std::array<double, 256>& step_cost);

}  // namespace rfbsim::sim
