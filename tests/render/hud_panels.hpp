// SPDX-License-Identifier: GPL-2.0-or-later
// HUD panels for the HUD tests, built from plain lines of text.
#pragma once

#include <initializer_list>
#include <string>

#include "render/hud.hpp"

namespace rfbsim::test {

/// A panel with one line per text, in order, at `anchor`.
inline sim::HudPanel panel_of(std::initializer_list<std::string> texts,
                              sim::HudAnchor anchor = sim::HudAnchor::TopLeft) {
  sim::HudPanel panel;
  for (const auto& text : texts) panel.lines.push_back({text});
  panel.anchor = anchor;
  return panel;
}

}  // namespace rfbsim::test
