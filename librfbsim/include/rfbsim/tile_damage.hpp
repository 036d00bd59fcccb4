// SPDX-License-Identifier: GPL-2.0-or-later
// rfbsim::TileDamage: which fixed-size tiles differ between two frames of the same size.
#pragma once

#include <vector>

#include "rfbsim/frame.hpp"

namespace rfbsim {

/// A rectangle in pixels; x, y is the top-left corner.
struct PixelRect {
  int x = 0;
  int y = 0;
  int w = 0;
  int h = 0;
  friend bool operator==(const PixelRect&, const PixelRect&) = default;
};

/// Compares frames tile by tile so that only the tiles that changed are copied and encoded.
/// Tiles at the right and bottom edges are clipped to the frame.
class TileDamage {
 public:
  /// Default tile edge in pixels: large enough that Tight encodes few rectangles, small enough that a
  /// walking avatar does not dirty the whole frame.
  static constexpr int kDefaultTileSize = 64;

  /// width, height: frame size in pixels (> 0); tile_size: tile edge in pixels (> 0).
  /// Throws std::invalid_argument on a non-positive argument.
  TileDamage(int width, int height, int tile_size = kDefaultTileSize);

  /// Marks every tile whose pixels differ between `before` and `after` (both of this object's size).
  /// Returns the number of changed tiles.
  int compare(const FrameView& before, const FrameView& after);
  /// Marks every tile as changed (a first frame, or a client that needs everything).
  void mark_all();

  /// Whether tile (column, row) changed in the last compare().
  [[nodiscard]] bool changed(int column, int row) const;
  /// Number of changed tiles.
  [[nodiscard]] int changed_count() const { return changed_count_; }
  /// Changed tiles as rectangles, horizontally adjacent tiles of one tile row merged, top to bottom.
  [[nodiscard]] std::vector<PixelRect> changed_rects() const;

  [[nodiscard]] int columns() const { return columns_; }
  [[nodiscard]] int rows() const { return rows_; }
  [[nodiscard]] int tile_size() const { return tile_size_; }

 private:
  int width_;
  int height_;
  int tile_size_;
  int columns_;
  int rows_;
  int changed_count_ = 0;
  std::vector<unsigned char> changed_;  // columns_ * rows_, row-major
};

}  // namespace rfbsim
