// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "map/distance_field.hpp"

using namespace rfbsim::sim;

TEST_CASE("the distance field is the exact Euclidean distance between cell centres") {
  GridMap map = grid_from_text({"..........", "..........", "..........", "..........", "..........",
                                "..........", "..........", ".........."},
                               0.5);
  map.occupied[static_cast<std::size_t>(3 * map.width + 4)] = 1;  // one wall cell at (4, 3)
  const DistanceField field(map);
  // Brute force: the nearest of the wall cell and the map's border (outside counts as wall).
  for (int row = 0; row < map.height; ++row) {
    for (int col = 0; col < map.width; ++col) {
      double best = std::numeric_limits<double>::infinity();
      for (int r = -1; r <= map.height; ++r) {
        for (int c = -1; c <= map.width; ++c) {
          if (!map.is_occupied(c, r)) continue;
          best = std::min(best, std::hypot(c - col, r - row) * map.resolution);
        }
      }
      INFO("cell " << col << "," << row);
      CHECK(field.at_cell({col, row}) == Approx(best).epsilon(1e-6));
    }
  }
  CHECK(field.at_cell({4, 3}) == 0.0);
  CHECK(field.at_cell({-1, 0}) == 0.0);
}

TEST_CASE("distance at a point and its gradient point away from the nearest wall") {
  const GridMap map = grid_from_text({"#########", "#.......#", "#.......#", "#.......#", "#########"}, 1.0);
  const DistanceField field(map);
  // One cell from the left wall's surface at x = 1: about 1 m.
  CHECK(field.at(2.5, 2.5) == Approx(1.5).margin(0.01));
  CHECK(field.at(1.5, 2.5) == Approx(0.5).margin(0.01));
  const Eigen::Vector2d g = field.gradient(1.7, 2.5);
  CHECK(g.x() == Approx(1.0).margin(1e-6));
  CHECK(g.y() == Approx(0.0).margin(1e-6));
  const Eigen::Vector2d up = field.gradient(4.5, 1.6);
  CHECK(up.y() > 0.99);
}
