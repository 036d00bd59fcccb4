// SPDX-License-Identifier: GPL-2.0-or-later
// The proxemic layer: the Gaussian at sample cells against the formula (standing: symmetric; walking:
// stretched ahead, not behind), the cutoff, floor rounding, max with what is there, and the analytic
// cutoff box against a brute-force scan of a large grid.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

#include "costmap_test_support.hpp"
#include "robot/costmap/proxemic_layer.hpp"

using namespace rfbsim::sim;
using costmap_test::person_at;

namespace {

// An 8 x 8 m grid at 0.05 m whose cell centres fall on multiples of 0.05 m, (0, 0) among them.
CostmapGrid centred_grid() { return CostmapGrid::sized(161, 161, 0.05, -4.025, -4.025); }

std::uint8_t at(const CostmapGrid& g, double x, double y) { return g.at_world(x, y, 99); }

// docs/sources.md's formula, written out again here: cov 0.25, amplitude 77, factor 5.
double formula(double x, double y, double sx2, double sy2) {
  return 77.0 * std::exp(-(x * x / (2.0 * sx2) + y * y / (2.0 * sy2)));
}

}  // namespace

TEST_CASE("a standing person is a circle: equal costs at equal distances, the formula's floor") {
  const ProxemicLayerParams params;
  const ProxemicLayer layer(params);
  CostmapGrid g = centred_grid();
  layer.stamp(g, person_at(0.0, 0.0), CellWindow::whole(g.width, g.height));
  // 77 exp(-0.5^2 / 0.5) = 46.70: floor gives 46 (rounding would give 47).
  CHECK(at(g, 0.5, 0.0) == 46);
  CHECK(at(g, -0.5, 0.0) == 46);
  CHECK(at(g, 0.0, 0.5) == 46);
  CHECK(at(g, 0.0, -0.5) == 46);
  CHECK(at(g, 0.0, 0.0) == 77);
  CHECK(at(g, 0.3, 0.4) == static_cast<int>(std::floor(formula(0.3, 0.4, 0.25, 0.25))));
  CHECK(at(g, -0.3, -0.4) == at(g, 0.3, 0.4));
  // Below the cutoff (10): 77 exp(-1.05^2 / 0.5) = 8.49 stays 0; 77 exp(-1) = 10.42 at 1.0 m is kept.
  CHECK(at(g, 1.0, 0.0) == 10);
  CHECK(at(g, 1.05, 0.0) == 0);
  CHECK(at(g, 0.0, -1.05) == 0);
  // Barely moving (below standing_speed 0.05 m/s) is still a circle.
  CostmapGrid slow = centred_grid();
  layer.stamp(slow, person_at(0.0, 0.0, 0.04, 0.0), CellWindow::whole(slow.width, slow.height));
  CHECK(slow.costs == g.costs);
}

TEST_CASE("a walking person's space is stretched ahead of them, where they are going") {
  const ProxemicLayerParams params;
  const ProxemicLayer layer(params);
  CostmapGrid g = centred_grid();
  layer.stamp(g, person_at(0.0, 0.0, 1.0, 0.0), CellWindow::whole(g.width, g.height));
  // Ahead: sx^2 = 0.25 (1 + 5 * 1) = 1.5, so 77 exp(-1 / 3) = 55.17 at 1 m; behind the plain 0.25: 10.42.
  CHECK(at(g, 1.0, 0.0) == 55);
  CHECK(at(g, 1.0, 0.0) == static_cast<int>(std::floor(formula(1.0, 0.0, 1.5, 0.25))));
  CHECK(at(g, -1.0, 0.0) == 10);
  CHECK(at(g, 1.0, 0.0) > at(g, -1.0, 0.0));
  // Ahead and to the side: x stretched, y not.
  CHECK(at(g, 0.8, 0.3) == static_cast<int>(std::floor(formula(0.8, 0.3, 1.5, 0.25))));
  CHECK(at(g, -0.8, 0.3) == static_cast<int>(std::floor(formula(-0.8, 0.3, 0.25, 0.25))));
  // Sideways is as for a standing person, and symmetric left and right.
  CHECK(at(g, 0.0, 0.5) == 46);
  CHECK(at(g, 0.0, -0.5) == 46);
  // Far ahead it reaches past where it would end behind: 77 exp(-2^2 / 3) = 20.3 at 2 m.
  CHECK(at(g, 2.0, 0.0) == 20);
  CHECK(at(g, -2.0, 0.0) == 0);
}

TEST_CASE("the stretch turns with the walking direction") {
  const ProxemicLayerParams params;
  const ProxemicLayer layer(params);
  CostmapGrid g = centred_grid();
  // Walking -y at 0.6 m/s: sx^2 = 0.25 * 4 = 1.0 ahead, i.e. toward -y.
  layer.stamp(g, person_at(0.0, 0.0, 0.0, -0.6), CellWindow::whole(g.width, g.height));
  CHECK(at(g, 0.0, -1.0) == static_cast<int>(std::floor(formula(1.0, 0.0, 1.0, 0.25))));  // 46.70
  CHECK(at(g, 0.0, -1.0) == 46);
  CHECK(at(g, 0.0, 1.0) == 10);
  // Diagonally (walking along (1, 1)), the cell ahead on the diagonal beats the one behind.
  CostmapGrid d = centred_grid();
  layer.stamp(d, person_at(0.0, 0.0, 0.7, 0.7), CellWindow::whole(d.width, d.height));
  CHECK(at(d, 0.5, 0.5) > at(d, -0.5, -0.5));
  const double front_variance = 0.25 * (1 + 5 * std::hypot(0.7, 0.7));
  CHECK(at(d, 0.5, 0.5) == static_cast<int>(std::floor(formula(std::hypot(0.5, 0.5), 0.0, front_variance, 0.25))));
}

TEST_CASE("each cell keeps the max of what it held and the person's cost") {
  const ProxemicLayer layer{ProxemicLayerParams{}};
  CostmapGrid g = centred_grid();
  std::fill(g.costs.begin(), g.costs.end(), std::uint8_t{30});
  layer.stamp(g, person_at(0.0, 0.0), CellWindow::whole(g.width, g.height));
  CHECK(at(g, 0.5, 0.0) == 46);  // raised
  CHECK(at(g, 1.0, 0.0) == 30);  // 10 < 30: kept
  // Two people: the max of both, not the sum.
  CostmapGrid two = centred_grid();
  layer.stamp(two, person_at(-0.5, 0.0), CellWindow::whole(two.width, two.height));
  layer.stamp(two, person_at(0.5, 0.0), CellWindow::whole(two.width, two.height));
  CHECK(at(two, 0.0, 0.0) == 46);
}

TEST_CASE("a person's stamp leaves the cells below the cutoff untouched") {
  const ProxemicLayer layer{ProxemicLayerParams{}};
  CostmapGrid g = centred_grid();
  std::fill(g.costs.begin(), g.costs.end(), std::uint8_t{30});
  layer.stamp(g, person_at(0.0, 0.0), CellWindow::whole(g.width, g.height));
  CHECK(at(g, 3.0, 0.0) == 30);  // far away: kept
  // Beyond 2 m the cost is below 77 exp(-8) < 0.03: every such cell still holds what it held.
  int changed = 0;
  for (int row = 0; row < g.height; ++row) {
    for (int col = 0; col < g.width; ++col) {
      if (g.cell_centre({col, row}).norm() > 2.0 && g.at({col, row}) != 30) ++changed;
    }
  }
  CHECK(changed == 0);
}

TEST_CASE("a proxemic stamp writes only inside its clip window") {
  const ProxemicLayer layer{ProxemicLayerParams{}};
  CostmapGrid g = centred_grid();
  const Cell middle = g.cell_of(0.0, 0.0);
  layer.stamp(g, person_at(0.0, 0.0), CellWindow{middle.col, 0, g.width - 1, g.height - 1});
  CHECK(at(g, 0.0, 0.0) == 77);
  CHECK(at(g, 0.5, 0.0) == 46);
  CHECK(at(g, -0.5, 0.0) == 0);
}

TEST_CASE("costs are capped at 252 and an amplitude at or below the cutoff gives nothing") {
  ProxemicLayerParams params;
  params.amplitude = 300.0;
  CHECK(proxemic_cost(300.0, params) == 252);
  CHECK(proxemic_cost(251.9, params) == 251);
  CHECK(proxemic_cost(9.99, params) == 0);
  CHECK(proxemic_cost(std::nan(""), params) == 0);
  params.amplitude = 10.0;
  CHECK(proxemic_bounds(person_at(0.0, 0.0), params).empty());
  CostmapGrid g = centred_grid();
  ProxemicLayer(params).stamp(g, person_at(0.0, 0.0), CellWindow::whole(g.width, g.height));
  CHECK(std::all_of(g.costs.begin(), g.costs.end(), [](std::uint8_t c) { return c == 0; }));
  CHECK(proxemic_bounds(person_at(std::nan(""), 0.0), ProxemicLayerParams{}).empty());
}

TEST_CASE("the analytic cutoff box is tight and the bounded stamp equals evaluating every cell") {
  const ProxemicLayerParams params;
  const ProxemicLayer layer(params);
  // Off-grid-centre positions, every quadrant of heading, several speeds.
  const std::vector<SeenPerson> people{
      person_at(0.013, -0.021, 0.0, 0.0),  person_at(0.2, 0.1, 1.3, 0.0),      person_at(-0.1, 0.3, -1.0, 0.4),
      person_at(0.07, -0.2, 0.3, -1.1),    person_at(0.0, 0.0, -0.5, -0.5),    person_at(0.3, 0.2, 0.0, 1.5),
      person_at(-0.2, 0.04, 0.9, 0.9)};
  for (const SeenPerson& p : people) {
    INFO("person at " << p.position.transpose() << " walking " << p.velocity.transpose());
    CostmapGrid bounded = centred_grid();
    layer.stamp(bounded, p, CellWindow::whole(bounded.width, bounded.height));
    const WorldBox box = proxemic_bounds(p, params);
    CostmapGrid every = centred_grid();
    double low_x = 1e9, high_x = -1e9, low_y = 1e9, high_y = -1e9;
    for (int row = 0; row < every.height; ++row) {
      for (int col = 0; col < every.width; ++col) {
        const Eigen::Vector2d c = every.cell_centre({col, row});
        const std::uint8_t cost_here = proxemic_cost(proxemic_value(p, c, params), params);
        every.set({col, row}, cost_here);
        if (cost_here == 0) continue;
        low_x = std::min(low_x, c.x());
        high_x = std::max(high_x, c.x());
        low_y = std::min(low_y, c.y());
        high_y = std::max(high_y, c.y());
      }
    }
    CHECK(bounded.costs == every.costs);
    // Every passing cell centre is in the box, and the box ends within a cell of the last ones.
    CHECK(box.min.x() <= low_x);
    CHECK(box.max.x() >= high_x);
    CHECK(box.min.y() <= low_y);
    CHECK(box.max.y() >= high_y);
    CHECK(low_x - box.min.x() < 0.05);
    CHECK(box.max.x() - high_x < 0.05);
    CHECK(low_y - box.min.y() < 0.05);
    CHECK(box.max.y() - high_y < 0.05);
  }
}

TEST_CASE("set_people leaves out non-finite positions and treats a non-finite velocity as standing") {
  ProxemicLayer layer{ProxemicLayerParams{}};
  const std::vector<SeenPerson> people{person_at(std::nan(""), 0.0), person_at(0.0, 0.0, std::nan(""), 1.0)};
  CHECK(layer.set_people(people) == 1);
  CostmapGrid social = centred_grid();
  CostmapGrid master = centred_grid();
  layer.update_costs(master, social, CellWindow::whole(master.width, master.height));
  CHECK(at(social, 0.5, 0.0) == 46);
  CHECK(at(social, 0.0, 0.5) == 46);
  CHECK(at(master, 0.0, -0.5) == 46);  // the master takes the max with the layer's costs
}
