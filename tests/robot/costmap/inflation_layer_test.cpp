// SPDX-License-Identifier: GPL-2.0-or-later
// The inflation layer: the kernel against docs/sources.md's formula, a single lethal cell counted per cost
// class (as nav2's inflation test does), nearest-source maxima, clipping to the dirty window, and the
// static cache against a brute-force nearest-lethal search.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>

#include "robot/costmap/inflation_layer.hpp"

using namespace rfbsim::sim;

namespace {

constexpr double kRes = 0.05;
constexpr double kInscribed = 0.16;

// docs/sources.md's formula, written out again here.
int expected_cost(double d, double inflation_radius = 0.3, double w = 3.0) {
  if (d == 0.0) return 254;
  if (d > inflation_radius + 1e-12) return 0;
  if (d <= kInscribed + 1e-12) return 253;
  return static_cast<int>(std::floor(252.0 * std::exp(-w * (d - kInscribed))));
}

CostmapGrid grid_with_lethal(int width, int height, std::initializer_list<Cell> lethal) {
  CostmapGrid grid = CostmapGrid::sized(width, height, kRes, 0.0, 0.0);
  for (const Cell& c : lethal) grid.set(c, cost::kLethal);
  return grid;
}

}  // namespace

TEST_CASE("inflation_cost follows the formula at d = 0, inside the inscribed radius, 0.2, 0.25, 0.3 and beyond") {
  const InflationLayerParams params;  // 0.3 m, 3.0
  CHECK(inflation_cost(0.0, kInscribed, params) == 254);
  CHECK(inflation_cost(0.05, kInscribed, params) == 253);
  CHECK(inflation_cost(0.16, kInscribed, params) == 253);
  // floor(252 exp(-3 (d - 0.16))): 223.50, 192.37, 165.58
  CHECK(inflation_cost(0.2, kInscribed, params) == 223);
  CHECK(inflation_cost(0.25, kInscribed, params) == 192);
  CHECK(inflation_cost(0.3, kInscribed, params) == 165);
  CHECK(inflation_cost(6 * kRes, kInscribed, params) == 165);  // 0.30000000000000004 still counts as 0.3
  CHECK(inflation_cost(0.31, kInscribed, params) == 0);
  // SEAN's local 0.1 m radius ends inside the inscribed disc: nothing beyond it, as in nav2.
  const InflationLayerParams local{0.1, 3.0};
  CHECK(inflation_cost(0.1, kInscribed, local) == 253);
  CHECK(inflation_cost(0.15, kInscribed, local) == 0);
  // A larger radius and factor: floor(252 exp(-5 (0.4 - 0.16))) = floor(75.90).
  CHECK(inflation_cost(0.4, kInscribed, InflationLayerParams{0.5, 5.0}) == 75);
}

TEST_CASE("one lethal cell in a 13 x 13 grid: cells per cost class, and every cell equals the formula") {
  const InflationLayer layer(InflationLayerParams{}, kInscribed, kRes);
  REQUIRE(layer.radius_cells() == 6);
  CostmapGrid grid = grid_with_lethal(13, 13, {{6, 6}});
  layer.inflate(grid);
  std::map<std::string, int> classes;
  for (int row = 0; row < 13; ++row) {
    for (int col = 0; col < 13; ++col) {
      const int c = grid.at({col, row});
      const double d = kRes * std::hypot(col - 6, row - 6);
      INFO("cell " << col << ", " << row << " at " << d << " m");
      CHECK(c == expected_cost(d));
      classes[c == 254 ? "lethal" : c == 253 ? "inscribed" : c > 0 ? "inflated" : "free"]++;
    }
  }
  // Lattice points with dx^2 + dy^2 <= 10 (d <= 0.16 m): 37, the centre among them; with dx^2 + dy^2 <= 36
  // (d <= 0.3 m): 113.
  CHECK(classes["lethal"] == 1);
  CHECK(classes["inscribed"] == 36);
  CHECK(classes["inflated"] == 76);
  CHECK(classes["free"] == 13 * 13 - 113);
  // The samples the brief names: d = 0.2 (4, 0), 0.25 (3, 4), 0.3 (6, 0), just beyond (6, 1).
  CHECK(grid.at({10, 6}) == 223);
  CHECK(grid.at({9, 10}) == 192);
  CHECK(grid.at({12, 6}) == 165);
  CHECK(grid.at({12, 7}) == 0);
}

TEST_CASE("one lethal cell near the edge of a 10 x 10 grid: the kernel is clipped, values unchanged") {
  const InflationLayer layer(InflationLayerParams{}, kInscribed, kRes);
  CostmapGrid grid = grid_with_lethal(10, 10, {{2, 7}});
  layer.inflate(grid);
  for (int row = 0; row < 10; ++row) {
    for (int col = 0; col < 10; ++col) {
      CHECK(grid.at({col, row}) == expected_cost(kRes * std::hypot(col - 2, row - 7)));
    }
  }
}

TEST_CASE("with two lethal cells each cell gets the cost of the nearer one") {
  const InflationLayer layer(InflationLayerParams{}, kInscribed, kRes);
  CostmapGrid grid = grid_with_lethal(20, 5, {{3, 2}, {11, 2}});
  layer.inflate(grid);
  for (int col = 0; col < 20; ++col) {
    const double d = kRes * std::min(std::abs(col - 3), std::abs(col - 11));
    CHECK(grid.at({col, 2}) == expected_cost(d));
  }
  CHECK(grid.at({7, 2}) == 223);  // 4 cells from both
}

TEST_CASE("inflate keeps higher costs already there and only raises lower ones") {
  const InflationLayer layer(InflationLayerParams{}, kInscribed, kRes);
  CostmapGrid grid = grid_with_lethal(13, 13, {{6, 6}});
  grid.set({10, 6}, 240);  // above the 223 inflation would give
  grid.set({12, 6}, 100);  // below the 165
  layer.inflate(grid);
  CHECK(grid.at({10, 6}) == 240);
  CHECK(grid.at({12, 6}) == 165);
}

TEST_CASE("an inflation stamp writes only inside its clip window") {
  const InflationLayer layer(InflationLayerParams{}, kInscribed, kRes);
  CostmapGrid grid = CostmapGrid::sized(13, 13, kRes, 0.0, 0.0);
  layer.stamp(grid, {6, 6}, CellWindow{6, 0, 12, 12});
  CHECK(grid.at({6, 6}) == 254);
  CHECK(grid.at({10, 6}) == 223);
  CHECK(grid.at({5, 6}) == 0);  // left of the window: untouched
  CHECK(grid.at({2, 6}) == 0);
  // A centre outside the grid still reaches in.
  CostmapGrid edge = CostmapGrid::sized(13, 13, kRes, 0.0, 0.0);
  layer.stamp(edge, {-2, 6}, CellWindow::whole(13, 13));
  CHECK(edge.at({0, 6}) == 253);
  CHECK(edge.at({2, 6}) == 223);
  CHECK(edge.at({4, 6}) == 165);
  CHECK(edge.at({5, 6}) == 0);
}

TEST_CASE("inflating a wall block and scattered cells equals a brute-force nearest-lethal search") {
  // Only the block's rim is stamped; the interior must not change anything.
  const InflationLayer layer(InflationLayerParams{}, kInscribed, kRes);
  CostmapGrid grid = CostmapGrid::sized(30, 24, kRes, 0.0, 0.0);
  for (int row = 5; row < 15; ++row) {
    for (int col = 4; col < 12; ++col) grid.set({col, row}, cost::kLethal);
  }
  for (const Cell c : {Cell{20, 3}, Cell{21, 3}, Cell{25, 18}, Cell{16, 20}, Cell{29, 0}}) grid.set(c, cost::kLethal);
  const CostmapGrid lethal = grid;
  layer.inflate(grid);
  for (int row = 0; row < grid.height; ++row) {
    for (int col = 0; col < grid.width; ++col) {
      double nearest = 1e9;
      for (int r = 0; r < grid.height; ++r) {
        for (int c = 0; c < grid.width; ++c) {
          if (lethal.at({c, r}) == cost::kLethal) nearest = std::min(nearest, kRes * std::hypot(c - col, r - row));
        }
      }
      INFO("cell " << col << ", " << row);
      CHECK(grid.at({col, row}) == expected_cost(nearest));
    }
  }
}
