// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

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
  CHECK(map.column_of(-1.0) == 0);
  CHECK(map.column_of(-0.51) == 0);
  CHECK(map.column_of(-0.5) == 1);
  CHECK(map.column_of(-1.01) == -1);
  CHECK(map.row_of(2.99) == 1);
}

TEST_CASE("discs touch walls by their closest point") {
  const GridMap map = grid_from_text({"...", ".#.", "..."}, 1.0);  // wall cell covers [1,2] x [1,2]
  CHECK(map.disc_hits_wall(1.5, 1.5, 0.1));
  CHECK(map.disc_hits_wall(0.75, 1.5, 0.3));
  CHECK_FALSE(map.disc_hits_wall(0.65, 1.5, 0.3));
  CHECK_FALSE(map.disc_hits_wall(0.75, 0.75, 0.3));  // diagonal: 0.354 m from the corner
  CHECK(map.disc_hits_wall(0.8, 0.8, 0.3));         // 0.283 m from the corner
}

TEST_CASE("wall runs merge horizontally adjacent cells") {
  const GridMap map = grid_from_text({"###.#", ".....", "##..."}, 1.0);
  const auto runs = merge_wall_runs(map);
  REQUIRE(runs.size() == 3);
  CHECK(runs[0].row == 0);
  CHECK(runs[0].first_column == 0);
  CHECK(runs[0].columns == 2);
  CHECK(runs[1].row == 2);
  CHECK(runs[1].columns == 3);
  CHECK(runs[2].first_column == 4);
  CHECK(runs[2].columns == 1);
}

TEST_CASE("the built-in room is closed and its start is free") {
  const GridMap map = builtin_test_room();
  CHECK(map.width == 24);
  CHECK(map.height == 18);
  for (int col = 0; col < map.width; ++col) CHECK(map.is_occupied(col, 0));
  CHECK_FALSE(map.disc_hits_wall(3.5, -1.0, 0.3));
}
