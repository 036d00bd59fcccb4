// SPDX-License-Identifier: GPL-2.0-or-later
// The static layer and the costmap frame: sampling maps of another resolution and turned maps, the
// frame's extent, and the map's outside as lethal.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "robot/costmap/costmap_frame.hpp"
#include "robot/costmap/static_layer.hpp"

using namespace rfbsim::sim;

TEST_CASE("the static layer marks lethal exactly the costmap cells whose centres lie in walls") {
  // A 0.5 m room at 0.1 m per cell with one wall cell in the middle; the costmap has 0.05 m cells, so each
  // map cell is 2 x 2 costmap cells.
  const GridMap map = grid_from_text({"#####",
                                      "#...#",
                                      "#.#.#",
                                      "#...#",
                                      "#####"},
                                     0.1);
  const StaticLayer layer(map, frame_for_map(map, 0.05, 0));
  const CostmapGrid& lethal = layer.lethal();
  REQUIRE(lethal.width == 10);
  REQUIRE(lethal.height == 10);
  for (int row = 0; row < 10; ++row) {
    for (int col = 0; col < 10; ++col) {
      const bool border = col < 2 || row < 2 || col > 7 || row > 7;
      const bool middle = (col == 4 || col == 5) && (row == 4 || row == 5);
      INFO("cell " << col << ", " << row);
      CHECK(lethal.at({col, row}) == (border || middle ? cost::kLethal : cost::kFree));
    }
  }
  CHECK(layer.is_lethal({-1, 3}));  // beyond the frame
  CHECK_FALSE(layer.is_lethal({3, 3}));
}

TEST_CASE("a turned map: the frame is its bounding box, and cells outside the map are lethal") {
  GridMap map;
  map.width = 20;
  map.height = 10;
  map.resolution = 0.1;
  map.origin_x = 1.0;
  map.origin_y = 2.0;
  map.origin_yaw = std::numbers::pi / 6;
  map.occupied.assign(200, 0);
  map.occupied[5 * 20 + 10] = 1;  // one wall cell, (10, 5)
  const CostmapGrid frame = frame_for_map(map, 0.05, 0);
  // Corners (1, 2), (1 + 2 cos 30, 2 + 2 sin 30), (1 - sin 30, 2 + cos 30), and their sum: x from 0.5 to
  // 2.732, y from 2 to 3.866.
  CHECK(frame.origin_x == Approx(0.5));
  CHECK(frame.origin_y == Approx(2.0));
  CHECK(frame.width == 45);   // ceil(2.232 / 0.05)
  CHECK(frame.height == 38);  // ceil(1.866 / 0.05)
  const StaticLayer layer(map, frame);
  CHECK(layer.is_lethal({0, 0}));   // the lower-left corner of the box is left of the turned map
  CHECK(layer.is_lethal({44, 37}));
  const Eigen::Vector2d wall = map.cell_centre({10, 5});
  CHECK(layer.is_lethal(frame.cell_of(wall.x(), wall.y())));
  const Eigen::Vector2d open = map.cell_centre({4, 5});
  CHECK_FALSE(layer.is_lethal(frame.cell_of(open.x(), open.y())));
  // Every cell agrees with the map at its centre.
  int lethal_cells = 0;
  for (int row = 0; row < frame.height; ++row) {
    for (int col = 0; col < frame.width; ++col) {
      const Eigen::Vector2d c = frame.cell_centre({col, row});
      CHECK(layer.is_lethal({col, row}) == map.is_occupied_at(c.x(), c.y()));
      lethal_cells += layer.is_lethal({col, row}) ? 1 : 0;
    }
  }
  // The map's 2 m x 1 m is about 800 costmap cells of the box's 1710 (796 centres fall in free map
  // cells, counted by hand-written sampling); the rest, the wall among them, is lethal.
  CHECK(lethal_cells == 1710 - 796);
}

TEST_CASE("a 20 x 30 m map at 0.05 m gives a 400 x 600 frame, plus the margin all round") {
  GridMap map;
  map.width = 200;
  map.height = 300;
  map.resolution = 0.1;
  map.origin_x = -3.0;
  map.origin_y = 4.0;
  map.occupied.assign(200 * 300, 0);
  const CostmapGrid plain = frame_for_map(map, 0.05, 0);
  CHECK(plain.width == 400);
  CHECK(plain.height == 600);
  const CostmapGrid padded = frame_for_map(map, 0.05, 7);
  CHECK(padded.width == 414);
  CHECK(padded.height == 614);
  CHECK(padded.origin_x == Approx(-3.35));
  CHECK(padded.origin_y == Approx(3.65));
  map.origin_x = std::nan("");
  CHECK_THROWS_AS(frame_for_map(map, 0.05, 0), std::invalid_argument);
}

TEST_CASE("the static layer's bounds are the whole frame once, and master cells beyond the frame read lethal") {
  const GridMap map = grid_from_text({"....", "....", "....", "...."}, 0.05);
  const CostmapGrid frame = frame_for_map(map, 0.05, 0);
  StaticLayer layer(map, frame);
  CellWindow bounds;
  layer.update_bounds(bounds);
  CHECK(bounds.min_col == 0);
  CHECK(bounds.max_col == 3);
  CHECK(bounds.max_row == 3);
  CellWindow again;
  layer.update_bounds(again);
  CHECK(again.empty());
  // A 6 x 6 master whose cell (0, 0) is frame cell (-1, -1): a ring of master cells lies off the map.
  CostmapGrid master = CostmapGrid::sized(6, 6, 0.05, -0.05, -0.05);
  layer.update_costs(master, CellWindow::whole(6, 6), FrameOffset{-1, -1});
  for (int row = 0; row < 6; ++row) {
    for (int col = 0; col < 6; ++col) {
      const bool ring = col == 0 || row == 0 || col == 5 || row == 5;
      CHECK(master.at({col, row}) == (ring ? cost::kLethal : cost::kFree));
    }
  }
}
