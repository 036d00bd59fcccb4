// SPDX-License-Identifier: GPL-2.0-or-later
// Pedestrian routes on tiny maps: straight when nothing is in the way, around a shelf, through a gap
// narrower than the clearance, none into a closed room.
#include <catch2/catch.hpp>

#include "crowd/route_planner.hpp"

using namespace rfbsim::sim;

namespace {

// A map of cols x rows cells of `res` m with a one-cell wall border, plus the cells `blocked(col, row)` names.
template <typename Blocked>
GridMap bordered_map(int cols, int rows, double res, Blocked blocked) {
  GridMap map;
  map.width = cols;
  map.height = rows;
  map.resolution = res;
  map.occupied.assign(static_cast<std::size_t>(cols * rows), 0);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const bool border = row == 0 || col == 0 || row == rows - 1 || col == cols - 1;
      map.occupied[static_cast<std::size_t>(row * cols + col)] = border || blocked(col, row) ? 1 : 0;
    }
  }
  return map;
}

// Every leg of the route, from `from`, keeps the clearance the planner reports.
void check_legs_clear(const RoutePlanner& planner, const Eigen::Vector2d& from, const PlannedRoute& route) {
  Eigen::Vector2d at = from;
  for (const Eigen::Vector2d& w : route.waypoints) {
    INFO("leg to " << w.transpose());
    CHECK(planner.line_clear(at, w, route.clearance));
    at = w;
  }
}

// 5.5 m x 2.5 m at 0.5 m: two rooms with no way between them, split by a wall along column 4.
GridMap two_closed_rooms_map() {
  return grid_from_text({"###########", "#...#.....#", "#...#.....#", "#...#.....#", "###########"}, 0.5);
}

}  // namespace

TEST_CASE("in an open room the route is the goal itself") {
  const GridMap map = grid_from_text({"##########", "#........#", "#........#", "#........#", "#........#",
                                      "##########"},
                                     0.5);
  const RoutePlanner planner(map);
  const PlannedRoute route = planner.plan({1.0, 1.0}, {3.5, 1.5}, 0.3);
  REQUIRE(route.waypoints.size() == 1);
  CHECK(route.waypoints[0] == Eigen::Vector2d(3.5, 1.5));
  CHECK(route.clearance == 0.3);
}

TEST_CASE("a route goes around a shelf between start and goal, in a few waypoints") {
  // 10 m x 6 m at 0.25 m; a shelf 1 m thick from the bottom wall up to y = 4.25 m at x = 4.5..5.5.
  const RoutePlanner planner(bordered_map(40, 24, 0.25, [](int col, int row) {
    return col >= 18 && col < 22 && row < 17;  // the shelf
  }));
  const Eigen::Vector2d from(2.0, 1.5);
  const Eigen::Vector2d to(8.0, 1.5);
  CHECK_FALSE(planner.line_clear(from, to, 0.3));
  const PlannedRoute route = planner.plan(from, to, 0.3);
  REQUIRE(!route.waypoints.empty());
  CHECK(route.clearance == 0.3);
  CHECK(route.waypoints.back() == to);
  CHECK(route.waypoints.size() <= 4);
  check_legs_clear(planner, from, route);
  // Over the shelf's top (y = 4.25) with the clearance: some waypoint lies above y = 4.25 + 0.3.
  bool over = false;
  for (const Eigen::Vector2d& w : route.waypoints) over = over || w.y() > 4.5;
  CHECK(over);
}

TEST_CASE("a gap narrower than the clearance is still used when it is the only way") {
  // One-cell (0.5 m) door in a wall: no cell in it keeps 0.3 m from both sides, so the planner falls back.
  const GridMap map = grid_from_text({"###########", "#.........#", "#.........#", "#####.#####", "#.........#",
                                      "#.........#", "###########"},
                                     0.5);
  const RoutePlanner planner(map);
  const PlannedRoute route = planner.plan({1.0, 1.0}, {4.0, 2.25}, 0.3);
  REQUIRE(!route.waypoints.empty());
  CHECK(route.clearance == 0.15);
  CHECK(route.waypoints.back() == Eigen::Vector2d(4.0, 2.25));
  check_legs_clear(planner, {1.0, 1.0}, route);
}

TEST_CASE("no route into a closed room") {
  const RoutePlanner planner(two_closed_rooms_map());
  CHECK(planner.plan({1.0, 1.0}, {4.0, 1.0}, 0.3).waypoints.empty());
}

TEST_CASE("a goal inside a wall moves to the nearest free cell") {
  const RoutePlanner planner(two_closed_rooms_map());
  // (2.25, 1.25) is in the dividing wall (column 4); the nearest free cell centre is (1.75, 1.25).
  const PlannedRoute route = planner.plan({1.0, 1.0}, {2.1, 1.25}, 0.0);
  REQUIRE(route.waypoints.size() == 1);
  CHECK(route.waypoints[0].x() == Approx(1.75));
  CHECK(route.waypoints[0].y() == Approx(1.25));
}

namespace {

// 6 m x 4 m at 0.05 m with a wall one cell (5 cm) thick at x = 3.0 m, open between y = 1.6 and 2.4 when
// `door`: a fine map, where the search steps between blocks of 4 x 4 cells.
GridMap thin_wall_map(bool door) {
  return bordered_map(120, 80, 0.05, [door](int col, int row) {
    const double y = (row + 0.5) * 0.05;
    return col == 60 && !(door && y > 1.6 && y < 2.4);
  });
}

}  // namespace

TEST_CASE("on a fine map the route goes through the door of a wall one cell thick, never through the wall") {
  const RoutePlanner with_door(thin_wall_map(true));
  const PlannedRoute route = with_door.plan({1.0, 1.0}, {5.0, 1.0}, 0.3);
  REQUIRE(!route.waypoints.empty());
  CHECK(route.clearance == 0.3);
  check_legs_clear(with_door, {1.0, 1.0}, route);
  // Every leg that crosses x = 3 crosses it in the door.
  Eigen::Vector2d at(1.0, 1.0);
  int crossings = 0;
  for (const Eigen::Vector2d& w : route.waypoints) {
    if ((at.x() - 3.0) * (w.x() - 3.0) < 0.0) {
      const double y = at.y() + (w.y() - at.y()) * (3.0 - at.x()) / (w.x() - at.x());
      CHECK(y > 1.6);
      CHECK(y < 2.4);
      ++crossings;
    }
    at = w;
  }
  CHECK(crossings == 1);
  // Without the door there is no way at any clearance: the coarse steps do not jump the thin wall.
  const RoutePlanner closed(thin_wall_map(false));
  CHECK(closed.plan({1.0, 1.0}, {5.0, 1.0}, 0.3).waypoints.empty());
  CHECK(closed.plan({2.9, 1.0}, {3.1, 1.0}, 0.3).waypoints.empty());
}

TEST_CASE("a door 0.75 m or wider keeps the full clearance wherever it falls on the search's blocks") {
  // 6 m x 4 m at 0.05 m, a wall 0.2 m thick at x = 2.9..3.1 with a door 0.65..0.9 m wide, shifted by whole
  // cells against the 4 x 4 blocks the search steps between. At the full 0.3 m clearance only the middle of
  // a 0.65 m door is walkable, one cell wide, and the blocks' stand-ins do not always line up along it:
  // such a door is passed at half the clearance. From 0.75 m on, the walkable strip is wide enough.
  for (const int width_cells : {13, 14, 15, 16, 17, 18}) {
    for (int shift = 0; shift < 4; ++shift) {
      const int first_open_row = 30 + shift;
      const RoutePlanner planner(bordered_map(120, 80, 0.05, [&](int col, int row) {
        return col >= 58 && col < 62 && !(row >= first_open_row && row < first_open_row + width_cells);
      }));
      INFO("door " << width_cells * 5 << " cm wide from row " << first_open_row);
      const PlannedRoute route = planner.plan({1.0, 1.0}, {5.0, 1.0}, 0.3);
      REQUIRE(!route.waypoints.empty());
      CHECK(route.clearance >= (width_cells >= 15 ? 0.3 : 0.15));
      check_legs_clear(planner, {1.0, 1.0}, route);
    }
  }
}

TEST_CASE("no step slips between wall cells that touch at a corner, even at no clearance") {
  // A one-cell wall as a 45 degree staircase from corner to corner of a 4 m square at 0.05 m.
  const RoutePlanner planner(bordered_map(80, 80, 0.05, [](int col, int row) { return col + row == 79; }));
  CHECK(planner.plan({1.0, 1.0}, {3.0, 3.0}, 0.3).waypoints.empty());
  CHECK(planner.plan({1.8, 1.8}, {2.2, 2.2}, 0.0).waypoints.empty());
}
