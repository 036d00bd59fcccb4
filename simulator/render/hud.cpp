// SPDX-License-Identifier: GPL-2.0-or-later
// HudRasterizer: UTF-8 lines to FreeType glyph bitmaps (cached), composited over a rounded translucent
// background, and panels placed in the frame by their anchors.
#include "render/hud.hpp"

#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <unordered_map>
#include <utility>

#ifndef RFBSIM_HUD_FONT_PATH  // set by CMake from its RFBSIM_HUD_FONT cache variable
#define RFBSIM_HUD_FONT_PATH "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"
#endif

namespace rfbsim::sim {

namespace {

constexpr int kMinPixels = 4;
constexpr int kMaxPixels = 256;  // bounds one glyph's bitmap, whatever scale a caller asks for
// A HUD uses a few dozen codepoints at two or three sizes; past this the cache is dropped and refilled.
constexpr std::size_t kMaxCachedGlyphs = 4096;

// Decodes UTF-8, skipping malformed bytes (a stray continuation, a truncated sequence, an overlong form,
// a surrogate): text from a scenario file must never stop the HUD.
std::vector<char32_t> decode_utf8(std::string_view text) {
  std::vector<char32_t> out;
  out.reserve(text.size());
  std::size_t i = 0;
  while (i < text.size()) {
    const auto lead = static_cast<unsigned char>(text[i]);
    int extra = 0;
    char32_t cp = 0;
    char32_t min = 0;
    if (lead < 0x80) {
      out.push_back(lead);
      ++i;
      continue;
    }
    if ((lead & 0xe0U) == 0xc0U) {
      extra = 1, cp = lead & 0x1fU, min = 0x80;
    } else if ((lead & 0xf0U) == 0xe0U) {
      extra = 2, cp = lead & 0x0fU, min = 0x800;
    } else if ((lead & 0xf8U) == 0xf0U) {
      extra = 3, cp = lead & 0x07U, min = 0x10000;
    } else {
      ++i;  // a continuation byte without a lead, or 0xf8..0xff
      continue;
    }
    bool ok = i + static_cast<std::size_t>(extra) < text.size();
    for (int k = 1; ok && k <= extra; ++k) {
      const auto next = static_cast<unsigned char>(text[i + static_cast<std::size_t>(k)]);
      ok = (next & 0xc0U) == 0x80U;
      cp = (cp << 6U) | (next & 0x3fU);
    }
    if (ok && cp >= min && cp <= 0x10ffff && (cp < 0xd800 || cp > 0xdfff)) {
      out.push_back(cp);
      i += static_cast<std::size_t>(extra) + 1;
    } else {
      ++i;  // resynchronise on the next byte
    }
  }
  return out;
}

// Control characters have no picture; some fonts map them to a box, so they are skipped before lookup.
bool printable(char32_t cp) { return cp >= 0x20 && !(cp >= 0x7f && cp < 0xa0); }

std::array<float, 3> rgb_of(std::uint32_t rgb) {
  return {static_cast<float>((rgb >> 16U) & 0xffU), static_cast<float>((rgb >> 8U) & 0xffU),
          static_cast<float>(rgb & 0xffU)};
}

std::uint8_t to_byte(float v) { return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }

// Coverage (0..1) of the pixel whose top-left corner is (x, y) by a w x h rectangle with corners rounded
// to radius r, sampled at the pixel's centre with a one-pixel ramp at the arc.
float rounded_rect_coverage(int x, int y, int w, int h, float r) {
  const float px = static_cast<float>(x) + 0.5f;
  const float py = static_cast<float>(y) + 0.5f;
  const float cx = std::clamp(px, r, static_cast<float>(w) - r);
  const float cy = std::clamp(py, r, static_cast<float>(h) - r);
  const float d = std::hypot(px - cx, py - cy);  // 0 everywhere but the corner squares
  if (d == 0.0f) return 1.0f;
  return std::clamp(r - d + 0.5f, 0.0f, 1.0f);
}

// A glyph rendered at one pixel size: 8-bit coverage, placed relative to the pen on the baseline.
struct Glyph {
  int left = 0;     // pixels from the pen to the bitmap's left column
  int top = 0;      // pixels from the baseline up to the bitmap's top row
  int width = 0;    // bitmap columns
  int rows = 0;     // bitmap rows
  int advance = 0;  // pixels the pen moves after this glyph
  std::vector<std::uint8_t> coverage;  // rows * width, top row first
};

// Vertical metrics of the face at one pixel size.
struct LineMetrics {
  int ascender = 0;  // pixels from the line's top to its baseline
  int height = 0;    // pixels from the line's top to its bottom (ascender + descender)
};

// One line ready to draw: glyphs with their pen positions, and the ink's horizontal extent.
struct LaidLine {
  std::vector<std::pair<const Glyph*, int>> glyphs;  // glyph, pen x in pixels
  std::uint32_t rgb = 0xffffff;
  LineMetrics metrics;
  int x_min = 0;  // leftmost ink or pen position (negative when the first glyph overhangs to the left)
  int x_max = 0;  // rightmost ink or pen position
};

}  // namespace

HudStyle hud_style_for(int body_pixels) {
  HudStyle style;
  const float body = static_cast<float>(std::clamp(body_pixels, kMinPixels, kMaxPixels));
  style.body_pixels = static_cast<int>(body);
  style.padding = static_cast<int>(std::lround(body * 0.6f));
  style.corner_radius = static_cast<int>(std::lround(body * 0.5f));
  style.line_spacing = static_cast<int>(std::lround(body * 0.18f));
  return style;
}

std::filesystem::path hud_font_path() {
  const char* env = std::getenv("RFBSIM_HUD_FONT");
  if (env != nullptr && *env != '\0') return env;
  return RFBSIM_HUD_FONT_PATH;
}

struct HudRasterizer::Impl {
  HudStyle style;
  FT_Library library = nullptr;
  FT_Face face = nullptr;
  int face_pixels = 0;  // size the face is set to
  // Key: codepoint << 16 | pixel size. nullopt: the font has no such glyph (looked up once).
  std::unordered_map<std::uint64_t, std::optional<Glyph>> glyphs;
  std::unordered_map<int, LineMetrics> metrics;
  // The last layout, returned again while its inputs stay the same.
  std::optional<Hud> last_hud;
  int last_width = 0;
  int last_height = 0;
  std::vector<PlacedHudImage> last_layout;

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() {
    if (face != nullptr) FT_Done_Face(face);
    if (library != nullptr) FT_Done_FreeType(library);
  }

  void set_pixels(int pixels) {
    if (pixels == face_pixels) return;
    if (FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(pixels)) == 0) face_pixels = pixels;
  }

  int pixels_for(float scale) const {
    if (!std::isfinite(scale)) scale = 1.0f;
    return static_cast<int>(std::clamp(std::lround(static_cast<float>(style.body_pixels) * scale),
                                       static_cast<long>(kMinPixels), static_cast<long>(kMaxPixels)));
  }

  const LineMetrics& line_metrics(int pixels) {
    if (const auto it = metrics.find(pixels); it != metrics.end()) return it->second;
    set_pixels(pixels);
    // Scalable faces give these rounded to whole pixels (26.6 fixed point).
    LineMetrics m;
    m.ascender = static_cast<int>(face->size->metrics.ascender >> 6);
    m.height = m.ascender + static_cast<int>(-face->size->metrics.descender >> 6);
    return metrics.emplace(pixels, m).first->second;
  }

  // The glyph for a codepoint at a size, rendered on first use; null when the font cannot draw it.
  const Glyph* glyph(char32_t cp, int pixels) {
    const std::uint64_t key = (static_cast<std::uint64_t>(cp) << 16U) | static_cast<std::uint64_t>(pixels);
    if (const auto it = glyphs.find(key); it != glyphs.end()) return it->second ? &*it->second : nullptr;
    std::optional<Glyph> made;
    const FT_UInt index = FT_Get_Char_Index(face, cp);
    set_pixels(pixels);
    if (index != 0 && face_pixels == pixels && FT_Load_Glyph(face, index, FT_LOAD_RENDER) == 0) {
      const FT_GlyphSlot slot = face->glyph;
      const FT_Bitmap& bitmap = slot->bitmap;
      if (bitmap.rows == 0 || bitmap.width == 0 || bitmap.pixel_mode == FT_PIXEL_MODE_GRAY) {
        Glyph g;
        g.left = slot->bitmap_left;
        g.top = slot->bitmap_top;
        g.width = static_cast<int>(bitmap.width);
        g.rows = static_cast<int>(bitmap.rows);
        g.advance = static_cast<int>((slot->advance.x + 32) >> 6);
        g.coverage.resize(static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.rows));
        // The pitch is negative for bottom-up bitmaps; walk rows by it either way.
        for (int row = 0; row < g.rows; ++row) {
          const unsigned char* src = bitmap.buffer + static_cast<std::ptrdiff_t>(row) * bitmap.pitch;
          std::copy(src, src + g.width, g.coverage.begin() + static_cast<std::ptrdiff_t>(row) * g.width);
        }
        made = std::move(g);
      }
    }
    const std::optional<Glyph>& cached = glyphs.emplace(key, std::move(made)).first->second;
    return cached ? &*cached : nullptr;
  }

  LaidLine lay_out(const HudLine& line) {
    LaidLine laid;
    const int pixels = pixels_for(line.scale);
    laid.rgb = line.rgb;
    laid.metrics = line_metrics(pixels);
    int pen = 0;
    for (const char32_t cp : decode_utf8(line.text)) {
      if (!printable(cp)) continue;
      const Glyph* g = glyph(cp, pixels);
      if (g == nullptr) continue;
      if (g->width > 0) {
        laid.x_min = std::min(laid.x_min, pen + g->left);
        laid.x_max = std::max(laid.x_max, pen + g->left + g->width);
      }
      laid.glyphs.emplace_back(g, pen);
      pen += g->advance;
    }
    laid.x_max = std::max(laid.x_max, pen);
    return laid;
  }
};

HudRasterizer::HudRasterizer(const std::filesystem::path& font, int body_pixels)
    : HudRasterizer(font, hud_style_for(body_pixels)) {}

HudRasterizer::HudRasterizer(const std::filesystem::path& font, const HudStyle& style)
    : impl_(std::make_unique<Impl>()) {
  impl_->style = style;
  impl_->style.body_pixels = std::clamp(style.body_pixels, kMinPixels, kMaxPixels);
  const std::string name = "HUD font '" + font.string() + "': ";
  if (FT_Init_FreeType(&impl_->library) != 0) throw std::runtime_error(name + "FreeType failed to start");
  const FT_Error error = FT_New_Face(impl_->library, font.c_str(), 0, &impl_->face);
  if (error == FT_Err_Cannot_Open_Resource) throw std::runtime_error(name + "cannot open the file");
  if (error == FT_Err_Unknown_File_Format) throw std::runtime_error(name + "not a font FreeType can read");
  if (error != 0) throw std::runtime_error(name + "FreeType error " + std::to_string(error));
  impl_->set_pixels(impl_->style.body_pixels);
  if (impl_->face_pixels != impl_->style.body_pixels) {
    throw std::runtime_error(name + "cannot be scaled to " + std::to_string(impl_->style.body_pixels) + " px");
  }
}

HudRasterizer::~HudRasterizer() = default;
HudRasterizer::HudRasterizer(HudRasterizer&&) noexcept = default;
HudRasterizer& HudRasterizer::operator=(HudRasterizer&&) noexcept = default;

const HudStyle& HudRasterizer::style() const { return impl_->style; }

HudImage HudRasterizer::render_panel(const HudPanel& panel) {
  HudImage image;
  if (panel.lines.empty()) return image;
  if (impl_->glyphs.size() > kMaxCachedGlyphs) impl_->glyphs.clear();  // before any glyph is borrowed
  const HudStyle& style = impl_->style;

  // Measure: the widest line's ink, and the lines' heights stacked with the spacing between them.
  std::vector<LaidLine> lines;
  int text_width = 0;
  int text_height = 0;
  for (const HudLine& line : panel.lines) {
    lines.push_back(impl_->lay_out(line));
    text_width = std::max(text_width, lines.back().x_max - lines.back().x_min);
    text_height += lines.back().metrics.height;
  }
  text_height += style.line_spacing * static_cast<int>(lines.size() - 1);
  image.width = text_width + 2 * style.padding;
  image.height = text_height + 2 * style.padding;
  image.rgba.resize(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4);

  // Background: one colour, its opacity scaled by the rounded rectangle's coverage.
  const float radius = std::min({static_cast<float>(style.corner_radius), static_cast<float>(image.width) / 2.0f,
                                 static_cast<float>(image.height) / 2.0f});
  const auto bg = rgb_of(style.background_rgb);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      std::uint8_t* p = &image.rgba[(static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                                     static_cast<std::size_t>(x)) * 4];
      p[0] = to_byte(bg[0]);
      p[1] = to_byte(bg[1]);
      p[2] = to_byte(bg[2]);
      p[3] = to_byte(static_cast<float>(style.background_alpha) *
                     rounded_rect_coverage(x, y, image.width, image.height, radius));
    }
  }

  // Text: each glyph's coverage as an opaque colour laid over the background ("over", straight alpha).
  int line_top = style.padding;
  for (const LaidLine& line : lines) {
    const auto colour = rgb_of(line.rgb);
    const int baseline = line_top + line.metrics.ascender;
    const int origin = style.padding - line.x_min;
    for (const auto& [g, pen] : line.glyphs) {
      for (int row = 0; row < g->rows; ++row) {
        const int y = baseline - g->top + row;
        if (y < 0 || y >= image.height) continue;
        for (int col = 0; col < g->width; ++col) {
          const int x = origin + pen + g->left + col;
          if (x < 0 || x >= image.width) continue;
          const float c = static_cast<float>(g->coverage[static_cast<std::size_t>(row * g->width + col)]) / 255.0f;
          if (c == 0.0f) continue;
          std::uint8_t* p = &image.rgba[(static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                                         static_cast<std::size_t>(x)) * 4];
          const float under = static_cast<float>(p[3]) / 255.0f * (1.0f - c);
          const float alpha = c + under;
          for (int k = 0; k < 3; ++k) {
            p[k] = to_byte((colour[static_cast<std::size_t>(k)] * c + static_cast<float>(p[k]) * under) / alpha);
          }
          p[3] = to_byte(alpha * 255.0f);
        }
      }
    }
    line_top += line.metrics.height + style.line_spacing;
  }
  return image;
}

std::vector<PlacedHudImage> HudRasterizer::layout(const Hud& hud, int frame_width, int frame_height) {
  if (impl_->last_hud && *impl_->last_hud == hud && impl_->last_width == frame_width &&
      impl_->last_height == frame_height) {
    return impl_->last_layout;
  }
  const HudStyle& style = impl_->style;
  std::vector<PlacedHudImage> placed;
  std::vector<HudAnchor> anchors;
  for (const HudPanel& panel : hud.panels) {
    HudImage image = render_panel(panel);
    if (image.width == 0) continue;
    placed.push_back({std::move(image), 0, 0});
    anchors.push_back(panel.anchor);
  }

  // Panels sharing an anchor form one column, top to bottom in the order given.
  for (const HudAnchor anchor : {HudAnchor::TopLeft, HudAnchor::TopRight, HudAnchor::Center, HudAnchor::BottomCenter}) {
    int column_height = -style.gap;
    for (std::size_t i = 0; i < placed.size(); ++i) {
      if (anchors[i] == anchor) column_height += placed[i].image.height + style.gap;
    }
    if (column_height < 0) continue;  // no panel here
    int y = style.margin;
    if (anchor == HudAnchor::Center) y = (frame_height - column_height) / 2;
    if (anchor == HudAnchor::BottomCenter) y = frame_height - style.margin - column_height;
    for (std::size_t i = 0; i < placed.size(); ++i) {
      if (anchors[i] != anchor) continue;
      const int w = placed[i].image.width;
      int x = style.margin;
      if (anchor == HudAnchor::TopRight) x = frame_width - style.margin - w;
      if (anchor == HudAnchor::Center || anchor == HudAnchor::BottomCenter) x = (frame_width - w) / 2;
      // Too big for the frame: keep the top-left (the start of the text) visible.
      placed[i].x = std::max(0, x);
      placed[i].y = std::max(0, y);
      y += placed[i].image.height + style.gap;
    }
  }

  impl_->last_hud = hud;
  impl_->last_width = frame_width;
  impl_->last_height = frame_height;
  impl_->last_layout = placed;
  return placed;
}

}  // namespace rfbsim::sim
