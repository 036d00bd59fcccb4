// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "map/grid_map.hpp"

using namespace rfbsim::sim;

TEST_CASE("text rows map top-first onto grid rows bottom-first") {
  const GridMap map = grid_from_text({"#..", "...", "..#"}, 0.5);
  CHECK(map.width == 3);
  CHECK(map.height == 3);
  CHECK(map.is_occupied(0, 2));  // top-left in the text
  CHECK(map.is_occupied(2, 0));  // bottom-right in the text
  CHECK_FALSE(map.is_occupied(1, 1));
  CHECK(map.is_occupied(-1, 0));  // outside counts as wall
  CHECK(map.is_occupied(0, 3));
  CHECK_THROWS_AS(grid_from_text({"##", "#"}, 1.0), std::invalid_argument);
}

TEST_CASE("world coordinates map to cells through origin and resolution") {
  GridMap map = grid_from_text({"....", "...."}, 0.5);
  map.origin_x = -1.0;
  map.origin_y = 2.0;
  CHECK(map.cell_of(-1.0, 2.0) == Cell{0, 0});
  CHECK(map.cell_of(-0.51, 2.0) == Cell{0, 0});
  CHECK(map.cell_of(-0.5, 2.0) == Cell{1, 0});
  CHECK(map.cell_of(-1.01, 2.0) == Cell{-1, 0});
  CHECK(map.cell_of(-1.0, 2.99) == Cell{0, 1});
  CHECK(map.cell_centre({1, 1}).isApprox(Eigen::Vector2d(-0.25, 2.75)));
}

TEST_CASE("a turned origin turns the grid about its lower-left corner") {
  GridMap map = grid_from_text({"....", "...."}, 1.0);  // 4 columns along the grid's x, 2 rows
  map.origin_x = 10.0;
  map.origin_y = 0.0;
  map.origin_yaw = M_PI / 2;  // the grid's columns now run along world +y
  CHECK(map.cell_of(9.5, 3.5) == Cell{3, 0});
  CHECK(map.cell_of(8.5, 0.5) == Cell{0, 1});
  CHECK_FALSE(map.contains(10.5, 0.5));  // world +x is the grid's -row direction
  const Eigen::Vector2d back = map.cell_centre({3, 1});
  CHECK(back.isApprox(Eigen::Vector2d(8.5, 3.5)));
  CHECK(map.cell_of(back.x(), back.y()) == Cell{3, 1});
}

TEST_CASE("rays stop at the first wall cell's edge, in any direction") {
  const GridMap map = grid_from_text({"#####", "#...#", "#...#", "#...#", "#####"}, 1.0);  // inside: [1,4]^2
  CHECK(map.ray_cast(2.5, 2.5, 0.0, 10.0) == Approx(1.5));
  CHECK(map.ray_cast(2.5, 2.5, M_PI, 10.0) == Approx(1.5));
  CHECK(map.ray_cast(2.5, 2.5, M_PI / 2, 10.0) == Approx(1.5));
  CHECK(map.ray_cast(2.2, 2.5, -M_PI / 2, 10.0) == Approx(1.5));
  CHECK(map.ray_cast(2.5, 2.5, M_PI / 4, 10.0) == Approx(1.5 * std::sqrt(2.0)));
  CHECK(map.ray_cast(2.5, 2.5, 0.0, 1.0) == Approx(1.0));  // capped at the range
  CHECK(map.ray_cast(0.5, 0.5, 0.0, 10.0) == 0.0);         // starts inside a wall
}

TEST_CASE("a box blocks the cells whose centres it covers") {
  GridMap map = grid_from_text({"......", "......", "......", "......"}, 0.5);
  map.block_box(1.5, 1.0, 1.0, 0.5, 0.0);  // x in [1, 2], y in [0.75, 1.25]: columns 2-3, rows 1-2
  CHECK(map.is_occupied_at(1.25, 0.875));
  CHECK(map.is_occupied_at(1.75, 1.125));
  CHECK_FALSE(map.is_occupied_at(0.75, 1.0));
  CHECK_FALSE(map.is_occupied_at(1.25, 0.4));
}

TEST_CASE("discs touch walls by their closest point") {
  const GridMap map = grid_from_text({"...", ".#.", "..."}, 1.0);  // wall cell covers [1,2] x [1,2]
  CHECK(map.disc_hits_wall(1.5, 1.5, 0.1));
  CHECK(map.disc_hits_wall(0.75, 1.5, 0.3));
  CHECK_FALSE(map.disc_hits_wall(0.65, 1.5, 0.3));
  CHECK_FALSE(map.disc_hits_wall(0.75, 0.75, 0.3));  // diagonal: 0.354 m from the corner
  CHECK(map.disc_hits_wall(0.8, 0.8, 0.3));         // 0.283 m from the corner
}

TEST_CASE("wall rectangles cover every wall cell exactly once, and few of them do") {
  const GridMap map = grid_from_text({"###.#", "###.#", ".....", "##..#"}, 1.0);
  const auto rects = merge_wall_rectangles(map);
  std::vector<int> cover(map.occupied.size(), 0);
  for (const WallRect& r : rects) {
    for (int row = r.first_row; row < r.first_row + r.rows; ++row) {
      for (int col = r.first_column; col < r.first_column + r.columns; ++col) {
        REQUIRE(map.is_occupied(col, row));
        ++cover[static_cast<std::size_t>(row * map.width + col)];
      }
    }
  }
  for (std::size_t i = 0; i < cover.size(); ++i) CHECK(cover[i] == (map.occupied[i] ? 1 : 0));
  // Bottom "##" and "#", then the 3x2 block and the 1x2 column at the top.
  CHECK(rects.size() == 4);
  const GridMap room = builtin_test_room();
  CHECK(merge_wall_rectangles(room).size() < 12);
}

TEST_CASE("the built-in room is closed and its start is free") {
  const GridMap map = builtin_test_room();
  CHECK(map.width == 24);
  CHECK(map.height == 18);
  for (int col = 0; col < map.width; ++col) CHECK(map.is_occupied(col, 0));
  CHECK_FALSE(map.disc_hits_wall(3.5, -1.0, 0.3));
}
