// SPDX-License-Identifier: GPL-2.0-or-later
// The likelihood field on a tiny map: exact distances between cell centres, the cap, and off the map.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "robot/sensing/likelihood_field.hpp"

using namespace rfbsim::sim;

TEST_CASE("likelihood field: distances to the nearest blocking cell, capped") {
  // 0.5 m cells; one wall cell in the middle of a 9 x 5 room whose border is wall too.
  const GridMap map = grid_from_text(
      {
          "#########",
          "#.......#",
          "#...#...#",
          "#.......#",
          "#########",
      },
      0.5);
  const LikelihoodField field(map, 0.9);
  CHECK(field.at_cell(4, 2) == 0.0);                               // the wall cell itself
  CHECK(field.at_cell(3, 2) == Approx(0.5));                       // beside it
  CHECK(field.at_cell(1, 2) == Approx(0.5));                       // next to the west wall
  CHECK(field.at_cell(2, 2) == Approx(0.9));                       // 1.0 m to both walls: capped
  CHECK(field.at_cell(1, 1) == Approx(0.5));
  CHECK(field.at_cell(3, 3) == Approx(0.5));                       // the top wall is one cell up
  CHECK(field.at_cell(6, 2) == Approx(0.9));                       // 1.0 m to every wall
  CHECK(field.at(3.25, 1.25) == Approx(field.at_cell(6, 2)));     // world point -> cell (6, 2)
  // Off the map and nonsense coordinates read the cap, as AMCL does.
  CHECK(field.at_cell(-1, 2) == Approx(0.9));
  CHECK(field.at_cell(2, 5) == Approx(0.9));
  CHECK(field.at(-0.1, 1.0) == Approx(0.9));
  CHECK(field.at(std::numeric_limits<double>::quiet_NaN(), 1.0) == Approx(0.9));
  CHECK(field.at(1e300, 1.0) == Approx(0.9));
  CHECK(field.distances().size() == 45);
}

TEST_CASE("likelihood field: diagonal distances are Euclidean, and a map turned in the world works") {
  GridMap map = grid_from_text(
      {
          "......",
          "......",
          "......",
          "#.....",
      },
      1.0);
  const LikelihoodField field(map, 10.0);
  // Cell (1, 1) is sqrt(2) cells from the wall cell (0, 0), nearer than the map's edge (2 cells away).
  CHECK(field.at_cell(1, 1) == Approx(std::sqrt(2.0)));
  CHECK(field.at_cell(2, 2) == Approx(2.0));  // sqrt(8) to the wall cell, 2 to the edge above row 3
  map.origin_x = 10.0;
  map.origin_yaw = std::numbers::pi / 2;  // the grid's +col axis is the world's +y
  const LikelihoodField turned(map, 10.0);
  // Map point (u, v) lies at world (10 - v, u): cell (0, 0) is around (9.5, 0.5), cell (1, 1) around (8.5, 1.5).
  CHECK(turned.at(9.5, 0.5) == 0.0);
  CHECK(turned.at(8.5, 1.5) == Approx(std::sqrt(2.0)));
  CHECK(turned.at(10.5, 0.5) == Approx(10.0));  // off the grid
}

TEST_CASE("likelihood field: the cap must be a positive distance") {
  const GridMap map = grid_from_text({"#.."}, 1.0);
  CHECK_THROWS_AS(LikelihoodField(map, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(LikelihoodField(map, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}
