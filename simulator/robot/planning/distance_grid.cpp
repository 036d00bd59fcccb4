// SPDX-License-Identifier: GPL-2.0-or-later
// DistanceGrid: a bucket-queue Dijkstra brushfire from the target cells over the free cells of the local costmap.
#include "robot/planning/distance_grid.hpp"

#include "robot/planning/grid_neighbours.hpp"

namespace rfbsim::sim {

void DistanceGrid::compute(const CostmapGrid& grid, const std::vector<std::int32_t>& targets) {
  width_ = grid.width;
  height_ = grid.height;
  metres_per_unit_ = static_cast<float>(grid.resolution / kStraight);
  const std::size_t n = grid.costs.size();
  units_.assign(n, kNone);
  for (auto& bucket : buckets_) bucket.clear();
  const std::uint8_t* costs = grid.costs.data();
  const auto walkable = [&](std::size_t i) { return costs[i] < cost::kInscribed; };

  std::size_t pending = 0;
  for (const std::int32_t target : targets) {
    if (target < 0 || static_cast<std::size_t>(target) >= n) continue;
    const auto i = static_cast<std::size_t>(target);
    if (!walkable(i) || units_[i] == 0) continue;
    units_[i] = 0;
    buckets_[0].push_back(target);
    ++pending;
  }
  // Dijkstra with a bucket queue: every step is 10 or 14 units, so while the cells at distance d are being
  // expanded, new entries land in other buckets (d + 10, d + 14 mod 15) and never in the one being read.
  constexpr std::uint32_t kBuckets = kDiagonal + 1;
  for (std::uint32_t d = 0; pending > 0; ++d) {
    std::vector<std::int32_t>& bucket = buckets_[d % kBuckets];
    pending -= bucket.size();
    for (const std::int32_t index : bucket) {
      const auto at = static_cast<std::size_t>(index);
      if (units_[at] != d) continue;  // stale: reached shorter since
      const int col = index % width_;
      const int row = index / width_;
      for (int k = 0; k < 8; ++k) {
        const int ncol = col + kNeighbourDc[k];
        const int nrow = row + kNeighbourDr[k];
        if (ncol < 0 || nrow < 0 || ncol >= width_ || nrow >= height_) continue;
        const std::size_t next = static_cast<std::size_t>(nrow) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(ncol);
        if (!walkable(next)) continue;
        std::uint32_t step = kStraight;
        if (k >= 4) {
          // No slipping diagonally past an obstacle's corner.
          const std::size_t side_a = static_cast<std::size_t>(row) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(ncol);
          const std::size_t side_b = static_cast<std::size_t>(nrow) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(col);
          if (!walkable(side_a) || !walkable(side_b)) continue;
          step = kDiagonal;
        }
        const std::uint32_t reached = d + step;
        if (reached < units_[next]) {
          units_[next] = reached;
          buckets_[reached % kBuckets].push_back(static_cast<std::int32_t>(next));
          ++pending;
        }
      }
    }
    bucket.clear();
  }
}

}  // namespace rfbsim::sim
