// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>
#include <vector>

#include "rfbsim/tile_damage.hpp"

using rfbsim::FrameView;
using rfbsim::PixelRect;
using rfbsim::TileDamage;

namespace {
struct Picture {
  int w, h;
  std::vector<std::uint8_t> bytes;
  Picture(int width, int height) : w(width), h(height), bytes(static_cast<std::size_t>(width * height * 4), 0) {}
  void set(int x, int y, std::uint8_t value) { bytes[static_cast<std::size_t>((y * w + x) * 4)] = value; }
  FrameView view() const { return {bytes.data(), w, h, 0}; }
};
}  // namespace

TEST_CASE("identical frames have no damage") {
  Picture a(100, 70), b(100, 70);
  TileDamage damage(100, 70, 32);
  CHECK(damage.columns() == 4);
  CHECK(damage.rows() == 3);
  CHECK(damage.compare(a.view(), b.view()) == 0);
  CHECK(damage.changed_rects().empty());
}

TEST_CASE("one changed pixel marks exactly its tile") {
  Picture a(100, 70), b(100, 70);
  b.set(40, 33, 255);  // column 1, row 1
  TileDamage damage(100, 70, 32);
  CHECK(damage.compare(a.view(), b.view()) == 1);
  CHECK(damage.changed(1, 1));
  CHECK_FALSE(damage.changed(0, 1));
  REQUIRE(damage.changed_rects().size() == 1);
  CHECK(damage.changed_rects()[0] == PixelRect{32, 32, 32, 32});
}

TEST_CASE("edge tiles are clipped to the frame") {
  Picture a(100, 70), b(100, 70);
  b.set(99, 69, 1);  // last pixel: tile (3, 2) covers x 96..99, y 64..69
  TileDamage damage(100, 70, 32);
  CHECK(damage.compare(a.view(), b.view()) == 1);
  CHECK(damage.changed_rects()[0] == PixelRect{96, 64, 4, 6});
}

TEST_CASE("adjacent changed tiles of a row merge into one rectangle") {
  Picture a(100, 70), b(100, 70);
  b.set(0, 0, 9);
  b.set(40, 10, 9);
  b.set(70, 5, 9);  // tiles 0, 1, 2 of row 0
  b.set(99, 40, 9); // tile 3 of row 1
  TileDamage damage(100, 70, 32);
  CHECK(damage.compare(a.view(), b.view()) == 4);
  const auto rects = damage.changed_rects();
  REQUIRE(rects.size() == 2);
  CHECK(rects[0] == PixelRect{0, 0, 96, 32});
  CHECK(rects[1] == PixelRect{96, 32, 4, 32});
}

TEST_CASE("strided views compare by their rows") {
  Picture a(8, 8), b(8, 8);
  std::vector<std::uint8_t> padded(static_cast<std::size_t>(8 * 40), 0);  // stride 40 bytes, 8 px of 4
  padded[static_cast<std::size_t>(5 * 40 + 6 * 4)] = 7;
  b.set(6, 5, 7);
  TileDamage damage(8, 8, 4);
  CHECK(damage.compare(b.view(), FrameView{padded.data(), 8, 8, 40}) == 0);
  CHECK(damage.compare(a.view(), FrameView{padded.data(), 8, 8, 40}) == 1);
  CHECK(damage.changed(1, 1));
}

TEST_CASE("mark_all marks every tile and bad sizes are refused") {
  TileDamage damage(100, 70, 32);
  damage.mark_all();
  CHECK(damage.changed_count() == 12);
  CHECK(damage.changed_rects().size() == 3);
  CHECK_THROWS_AS(TileDamage(0, 10, 8), std::invalid_argument);
  CHECK_THROWS_AS(TileDamage(10, 10, 0), std::invalid_argument);
}
