// SPDX-License-Identifier: GPL-2.0-or-later
// The HUD: a few lines of text on translucent panels over the 3D frame, as plain data (Hud), and their
// rasterization into RGBA images with FreeType (HudRasterizer). No GL here; GlHudLayer draws the images.
//
// Usage, once per frame, on the thread that owns the OffscreenGL context:
//   sim::HudRasterizer hud_raster(sim::hud_font_path());   // once; throws if the font is missing
//   sim::GlHudLayer hud_layer;                              // once, with the context current
//   gl.begin_frame();
//   renderer.draw(scene, w, h);
//   hud_layer.draw(hud_raster.layout(hud, w, h), w, h);     // cheap when `hud` did not change
//   server.submit(gl.read_frame());
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace rfbsim::sim {

/// One line of text.
struct HudLine {
  std::string text;            ///< UTF-8; glyphs the font lacks and malformed bytes are skipped
  float scale = 1.0f;          ///< text height relative to the body size: 1 = body, e.g. 1.5 for a title
  std::uint32_t rgb = 0xffffff;  ///< text colour, 0xRRGGBB
  bool operator==(const HudLine&) const = default;
};

/// Where a panel sits in the frame.
enum class HudAnchor {
  TopLeft,       ///< HudStyle::margin from the top and left edges
  TopRight,      ///< HudStyle::margin from the top and right edges
  Center,        ///< centred both ways (e.g. the completion code)
  BottomCenter,  ///< centred horizontally, HudStyle::margin from the bottom edge
};

/// A block of lines on one rounded background. Panels sharing an anchor form one column, top to bottom in
/// the order given, HudStyle::gap apart; the column as a whole sits at the anchor.
struct HudPanel {
  std::vector<HudLine> lines;  ///< top to bottom; a panel without lines is not drawn
  HudAnchor anchor = HudAnchor::TopLeft;
  bool operator==(const HudPanel&) const = default;
};

/// Everything the HUD shows this frame; no panels = nothing drawn. Compare with the last one to know
/// whether the frame must be drawn again.
struct Hud {
  std::vector<HudPanel> panels;
  bool operator==(const Hud&) const = default;
};

/// An RGBA8 picture with straight (not premultiplied) alpha, top row first, rows tightly packed.
struct HudImage {
  int width = 0;                   ///< pixels
  int height = 0;                  ///< rows
  std::vector<std::uint8_t> rgba;  ///< width * height * 4 bytes
  bool operator==(const HudImage&) const = default;
};

/// A panel's image and where it goes.
struct PlacedHudImage {
  HudImage image;
  int x = 0;  ///< left column in frame pixels
  int y = 0;  ///< top row in frame pixels, counted down from the top of the frame
  bool operator==(const PlacedHudImage&) const = default;
};

/// How panels look. The frames are JPEG-compressed on their way to the browser, so the defaults favour
/// large, opaque text on a dark background.
struct HudStyle {
  int body_pixels = 22;                   ///< body text size in pixels (the font's em height)
  int padding = 13;                       ///< pixels between a panel's edge and its text
  int corner_radius = 11;                 ///< pixels; the background's corners are rounded and antialiased
  int margin = 16;                        ///< pixels between a corner-anchored panel and the frame's edges
  int gap = 8;                            ///< pixels between stacked panels
  int line_spacing = 4;                   ///< extra pixels between lines, on top of the font's own
  std::uint32_t background_rgb = 0x12161c;  ///< 0xRRGGBB, nearly black
  std::uint8_t background_alpha = 170;    ///< 0..255, the background's opacity (text is opaque)
};

/// The style for a body size: padding, corner radius and line spacing scale with it; margin and gap do not.
HudStyle hud_style_for(int body_pixels);

/// Finds the font: the RFBSIM_HUD_FONT environment variable if set and not empty, else the path CMake found
/// at configure time (DejaVuSans.ttf from fonts-dejavu-core).
std::filesystem::path hud_font_path();

/// Turns panels of text into images with FreeType. Owns the FreeType library and face, and a cache of
/// glyph bitmaps per (codepoint, pixel size), so re-rasterizing a HUD that changes once a second is cheap.
/// Not thread-safe; one per render thread.
class HudRasterizer {
 public:
  /// Loads `font` with the style for `body_pixels` (hud_style_for). Throws std::runtime_error naming the
  /// file when it cannot be read or is not a font.
  explicit HudRasterizer(const std::filesystem::path& font, int body_pixels = 22);
  /// Loads `font` with an explicit style (body_pixels clamped to 4..256). Throws as above.
  HudRasterizer(const std::filesystem::path& font, const HudStyle& style);
  ~HudRasterizer();
  HudRasterizer(HudRasterizer&&) noexcept;
  HudRasterizer& operator=(HudRasterizer&&) noexcept;
  HudRasterizer(const HudRasterizer&) = delete;
  HudRasterizer& operator=(const HudRasterizer&) = delete;

  /// Every panel that has lines, rendered and placed in a frame of `frame_width` x `frame_height` pixels
  /// by its anchor, in the order of hud.panels. Panels larger than the frame are placed at its top-left
  /// edge and clipped when drawn. The last result is remembered: the same hud and size again only
  /// costs a copy.
  std::vector<PlacedHudImage> layout(const Hud& hud, int frame_width, int frame_height);
  /// One panel: padding, a rounded translucent background, antialiased text, each line left-aligned.
  /// Empty (0 x 0) when the panel has no lines.
  HudImage render_panel(const HudPanel& panel);

  /// The style in use.
  [[nodiscard]] const HudStyle& style() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::sim
