// SPDX-License-Identifier: GPL-2.0-or-later
// HudRasterizer: panel sizes, background and text pixels, anchors in a 1280x720 frame, bad text, bad fonts.
#include "render/hud.hpp"

#include <array>
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>

#include "hud_panels.hpp"

namespace {

using rfbsim::sim::Hud;
using rfbsim::sim::HudAnchor;
using rfbsim::sim::HudImage;
using rfbsim::sim::HudLine;
using rfbsim::sim::HudPanel;
using rfbsim::sim::HudRasterizer;
using rfbsim::test::panel_of;

std::array<int, 4> at(const HudImage& image, int x, int y) {
  const std::uint8_t* p = &image.rgba[static_cast<std::size_t>((y * image.width + x) * 4)];
  return {p[0], p[1], p[2], p[3]};
}

// Pixels whose alpha is above the background's: where the glyphs are.
int ink(const HudImage& image, int above_alpha) {
  int count = 0;
  for (std::size_t i = 3; i < image.rgba.size(); i += 4) count += image.rgba[i] > above_alpha ? 1 : 0;
  return count;
}

}  // namespace

TEST_CASE("a longer line makes a wider panel of the same height and every line adds the same height") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  const HudImage short_line = raster.render_panel(panel_of({"Time left"}));
  const HudImage long_line = raster.render_panel(panel_of({"Time left 3:12"}));
  CHECK(long_line.width > short_line.width);
  CHECK(long_line.height == short_line.height);
  CHECK(long_line.rgba.size() == static_cast<std::size_t>(long_line.width * long_line.height * 4));

  const HudImage two = raster.render_panel(panel_of({"Time left", "Time left"}));
  const HudImage three = raster.render_panel(panel_of({"Time left", "Time left", "Time left"}));
  CHECK(two.width == short_line.width);
  CHECK(three.height - two.height == two.height - short_line.height);
  // One 22 px line: at least the body size, at most twice it (ascender + descender + spacing).
  const int line = two.height - short_line.height;
  CHECK(line >= 22);
  CHECK(line <= 44);
  CHECK(short_line.height - 2 * raster.style().padding >= 22);
}

TEST_CASE("a title at scale 1.5 is about half again as tall and wide as body text") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  const int padding = 2 * raster.style().padding;
  const HudImage body = raster.render_panel(panel_of({"Well done!"}));
  HudPanel title = panel_of({"Well done!"});
  title.lines[0].scale = 1.5f;
  const HudImage big = raster.render_panel(title);
  const double wide = static_cast<double>(big.width - padding) / (body.width - padding);
  const double tall = static_cast<double>(big.height - padding) / (body.height - padding);
  CHECK(wide >= 1.35);
  CHECK(wide <= 1.65);
  CHECK(tall >= 1.35);
  CHECK(tall <= 1.65);
}

TEST_CASE("the countdown panel keeps its width as the seconds tick since digits share one width") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  const int width = raster.render_panel(panel_of({"Time left 3:00"})).width;
  for (int s = 1; s < 60; ++s) {
    char text[32];
    std::snprintf(text, sizeof text, "Time left 3:%02d", s);
    INFO(text);
    CHECK(raster.render_panel(panel_of({text})).width == width);
  }
}

TEST_CASE("the background has the style's colour and opacity with transparent rounded corners") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  const auto& style = raster.style();
  CHECK(style.background_alpha == 170);
  const HudImage image = raster.render_panel(panel_of({"HHHH"}));
  const int w = image.width;
  const int h = image.height;
  // The padding band beside the text: background exactly, all the way down between the corners.
  for (int y = style.corner_radius; y < h - style.corner_radius; ++y) {
    for (const int x : {0, style.padding - 1, w - style.padding, w - 1}) {
      INFO("x " << x << " y " << y);
      REQUIRE(at(image, x, y) == std::array<int, 4>{0x12, 0x16, 0x1c, 170});
    }
  }
  for (const auto& [x, y] : {std::pair{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}}) {
    CHECK(at(image, x, y)[3] == 0);
  }
  // The arc is antialiased: some corner pixels are partly covered.
  int partial = 0;
  for (int y = 0; y < style.corner_radius; ++y) {
    for (int x = 0; x < style.corner_radius; ++x) partial += at(image, x, y)[3] > 0 && at(image, x, y)[3] < 170;
  }
  CHECK(partial > 0);
}

TEST_CASE("glyph pixels are the line's colour and opaque and lie inside the padding") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  const int pad = raster.style().padding;
  HudPanel panel = panel_of({"HHHH", "IIII"});
  panel.lines[1].rgb = 0xff3020;
  const HudImage image = raster.render_panel(panel);
  const int half = image.height / 2;
  int white = 0;
  int red = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const auto p = at(image, x, y);
      if (p[3] <= 170) continue;
      INFO("x " << x << " y " << y);
      REQUIRE(x >= pad);
      REQUIRE(x < image.width - pad);
      REQUIRE(y >= pad);
      REQUIRE(y < image.height - pad);
      white += p == std::array<int, 4>{255, 255, 255, 255} && y < half;
      red += p == std::array<int, 4>{0xff, 0x30, 0x20, 255} && y >= half;
    }
  }
  // Hinted stems of H and I at 22 px are whole pixels wide: dozens of fully covered pixels per line.
  CHECK(white > 40);
  CHECK(red > 40);
}

TEST_CASE("a larger body size makes a proportionally larger panel") {
  const auto font = rfbsim::sim::hud_font_path();
  HudRasterizer small(font, 22);
  HudRasterizer large(font, 44);
  CHECK(large.style().padding == 2 * small.style().padding);
  const HudImage a = small.render_panel(panel_of({"Task 2 of 3: Follow the robot"}));
  const HudImage b = large.render_panel(panel_of({"Task 2 of 3: Follow the robot"}));
  const double ratio = static_cast<double>(b.width) / a.width;
  CHECK(ratio >= 1.9);
  CHECK(ratio <= 2.1);
  CHECK(b.height >= 2 * a.height - 4);
  CHECK(b.height <= 2 * a.height + 4);
}

TEST_CASE("Latin-1 letters are drawn and malformed or unknown characters are skipped") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  const auto width = [&](const std::string& text) { return raster.render_panel(panel_of({text})).width; };
  CHECK(ink(raster.render_panel(panel_of({"\xc3\xa9"})), 170) > ink(raster.render_panel(panel_of({"e"})), 170));
  CHECK(width("Z\xc3\xbcrich caf\xc3\xa9 \xc2\xa9") > width("Zrich caf"));
  const int a = width("A");
  CHECK(width("A\xff\xfe") == a);                 // bytes that never occur in UTF-8
  CHECK(width("A\xc3") == a);                     // a sequence cut short
  CHECK(width("A\x80") == a);                     // a stray continuation byte
  CHECK(width("A\xc0\xaf") == a);                 // an overlong '/'
  CHECK(width("A\xed\xa0\x80") == a);             // a UTF-16 surrogate
  CHECK(width("A\xf4\x8f\xbf\xbd") == a);         // U+10FFFD: private use, in no font
  CHECK(width("A\t\n\x7f") == a);                 // control characters
  CHECK(width("A\xf4\x8f\xbf") == a);             // a four-byte sequence cut short
  // An empty line keeps its height and has no width beyond the padding.
  const HudImage empty = raster.render_panel(panel_of({""}));
  CHECK(empty.width == 2 * raster.style().padding);
  CHECK(empty.height == raster.render_panel(panel_of({"A"})).height);
  // No lines: no panel.
  const HudImage none = raster.render_panel(HudPanel{});
  CHECK(none.width == 0);
  CHECK(none.height == 0);
  CHECK(none.rgba.empty());
}

TEST_CASE("rendering is deterministic whether glyphs come from the cache or the font") {
  const auto font = rfbsim::sim::hud_font_path();
  HudRasterizer warm(font);
  const HudPanel panel = panel_of({"Task 2 of 3: Follow the robot", "Following: 12 / 30 s"});
  const HudImage first = warm.render_panel(panel);
  CHECK(warm.render_panel(panel) == first);
  HudRasterizer cold(font);
  CHECK(cold.render_panel(panel) == first);
}

TEST_CASE("anchors place panels in a 1280x720 frame at the margins and the centre") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  Hud hud;
  hud.panels = {panel_of({"Task 2 of 3: Follow the robot"}, HudAnchor::TopLeft),
                panel_of({"Time left 3:12"}, HudAnchor::TopRight),
                panel_of({"Well done!", "Your completion code: C1A2B3"}, HudAnchor::Center),
                panel_of({"Following: 12 / 30 s"}, HudAnchor::BottomCenter)};
  const auto placed = raster.layout(hud, 1280, 720);
  REQUIRE(placed.size() == 4);
  CHECK(raster.style().margin == 16);
  CHECK(placed[0].x == 16);
  CHECK(placed[0].y == 16);
  CHECK(placed[1].x + placed[1].image.width == 1280 - 16);
  CHECK(placed[1].y == 16);
  CHECK(placed[2].x == (1280 - placed[2].image.width) / 2);
  CHECK(placed[2].y == (720 - placed[2].image.height) / 2);
  CHECK(placed[3].x == (1280 - placed[3].image.width) / 2);
  CHECK(placed[3].y + placed[3].image.height == 720 - 16);
  // Each image is the panel rendered on its own.
  CHECK(placed[2].image == raster.render_panel(hud.panels[2]));
}

TEST_CASE("panels sharing an anchor stack top to bottom and empty panels are left out") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  const int gap = raster.style().gap;
  Hud hud;
  hud.panels = {panel_of({"Task 2 of 3"}), HudPanel{}, panel_of({"Following: 12 / 30 s", "Time left 3:12"}),
                panel_of({"Well done!"}, HudAnchor::Center), panel_of({"C1A2B3"}, HudAnchor::Center),
                panel_of({"one"}, HudAnchor::BottomCenter), panel_of({"two"}, HudAnchor::BottomCenter)};
  const auto p = raster.layout(hud, 1280, 720);
  REQUIRE(p.size() == 6);
  CHECK(p[0].y == 16);
  CHECK(p[1].x == 16);
  CHECK(p[1].y == 16 + p[0].image.height + gap);
  // The centred column as a whole is centred.
  const int column = p[2].image.height + gap + p[3].image.height;
  CHECK(p[2].y == (720 - column) / 2);
  CHECK(p[3].y == p[2].y + p[2].image.height + gap);
  CHECK(p[3].x == (1280 - p[3].image.width) / 2);
  // The bottom column ends at the margin, in reading order.
  CHECK(p[5].y + p[5].image.height == 720 - 16);
  CHECK(p[4].y + p[4].image.height + gap == p[5].y);
}

TEST_CASE("an empty HUD lays out nothing and the same HUD lays out the same images") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  CHECK(raster.layout(Hud{}, 1280, 720).empty());
  Hud hud;
  hud.panels = {panel_of({"Time left 3:12"})};
  const auto first = raster.layout(hud, 1280, 720);
  CHECK(raster.layout(hud, 1280, 720) == first);
  // A change of text or frame size is seen.
  CHECK(raster.layout(hud, 640, 360)[0].x == 16);
  hud.panels[0].anchor = HudAnchor::TopRight;
  CHECK(raster.layout(hud, 640, 360)[0].x == 640 - 16 - first[0].image.width);
  hud.panels[0].lines[0].text = "Time left 3:11";
  CHECK_FALSE(raster.layout(hud, 640, 360)[0].image == first[0].image);
}

TEST_CASE("a panel larger than the frame keeps its top-left corner in the frame") {
  HudRasterizer raster(rfbsim::sim::hud_font_path());
  Hud hud;
  hud.panels = {panel_of({"Well done! Your completion code: C1A2B3"}, HudAnchor::Center),
                panel_of({"Time left 3:12"}, HudAnchor::TopRight)};
  const auto placed = raster.layout(hud, 100, 20);
  REQUIRE(placed.size() == 2);
  CHECK(placed[0].x == 0);
  CHECK(placed[0].y == 0);
  CHECK(placed[1].x == 0);
  CHECK(placed[1].y == 16);
}

TEST_CASE("a missing font or a file that is not a font throws with the file's name") {
  CHECK_THROWS_WITH(HudRasterizer("/nonexistent/rfbsim-no-such-font.ttf"),
                    Catch::Contains("rfbsim-no-such-font.ttf") && Catch::Contains("cannot open"));
  const std::string not_font = "rfbsim_hud_test_not_a_font.ttf";
  std::ofstream(not_font) << "this is not a TrueType font\n";
  CHECK_THROWS_WITH(HudRasterizer(not_font), Catch::Contains(not_font) && Catch::Contains("not a font"));
  std::remove(not_font.c_str());
}

TEST_CASE("hud_font_path prefers the RFBSIM_HUD_FONT environment variable to the configured font") {
  const char* before = std::getenv("RFBSIM_HUD_FONT");
  const std::optional<std::string> saved = before != nullptr ? std::optional<std::string>(before) : std::nullopt;
  setenv("RFBSIM_HUD_FONT", "/opt/fonts/Other.ttf", 1);
  CHECK(rfbsim::sim::hud_font_path() == "/opt/fonts/Other.ttf");
  setenv("RFBSIM_HUD_FONT", "", 1);
  CHECK(rfbsim::sim::hud_font_path() == RFBSIM_HUD_FONT_PATH);
  unsetenv("RFBSIM_HUD_FONT");
  CHECK(rfbsim::sim::hud_font_path() == RFBSIM_HUD_FONT_PATH);
  if (saved) setenv("RFBSIM_HUD_FONT", saved->c_str(), 1);
}
