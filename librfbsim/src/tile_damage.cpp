// SPDX-License-Identifier: GPL-2.0-or-later
// Tile-by-tile frame comparison.
#include "rfbsim/tile_damage.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace rfbsim {

TileDamage::TileDamage(int width, int height, int tile_size)
    : width_(width), height_(height), tile_size_(tile_size) {
  if (width <= 0 || height <= 0 || tile_size <= 0) {
    throw std::invalid_argument("TileDamage: width, height and tile size must be positive");
  }
  columns_ = (width + tile_size - 1) / tile_size;
  rows_ = (height + tile_size - 1) / tile_size;
  changed_.assign(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(rows_), 0);
}

int TileDamage::compare(const FrameView& before, const FrameView& after) {
  std::fill(changed_.begin(), changed_.end(), 0);
  changed_count_ = 0;
  for (int row = 0; row < rows_; ++row) {
    const int y0 = row * tile_size_;
    const int y1 = std::min(y0 + tile_size_, height_);
    for (int column = 0; column < columns_; ++column) {
      const int x0 = column * tile_size_;
      const auto span = static_cast<std::size_t>(std::min(tile_size_, width_ - x0)) * 4U;
      const auto offset = static_cast<std::size_t>(x0) * 4U;
      // A tile changed if any of its row spans differs; stop at the first difference.
      for (int y = y0; y < y1; ++y) {
        if (std::memcmp(before.row(y) + offset, after.row(y) + offset, span) != 0) {
          changed_[static_cast<std::size_t>(row * columns_ + column)] = 1;
          ++changed_count_;
          break;
        }
      }
    }
  }
  return changed_count_;
}

void TileDamage::mark_all() {
  std::fill(changed_.begin(), changed_.end(), 1);
  changed_count_ = columns_ * rows_;
}

bool TileDamage::changed(int column, int row) const {
  return changed_[static_cast<std::size_t>(row * columns_ + column)] != 0;
}

std::vector<PixelRect> TileDamage::changed_rects() const {
  std::vector<PixelRect> rects;
  for (int row = 0; row < rows_; ++row) {
    const int y = row * tile_size_;
    const int h = std::min(tile_size_, height_ - y);
    int column = 0;
    while (column < columns_) {
      if (!changed(column, row)) {
        ++column;
        continue;
      }
      // Extend the run over adjacent changed tiles of this tile row.
      const int first = column;
      while (column < columns_ && changed(column, row)) ++column;
      const int x = first * tile_size_;
      rects.push_back({x, y, std::min(column * tile_size_, width_) - x, h});
    }
  }
  return rects;
}

}  // namespace rfbsim
