// SPDX-License-Identifier: GPL-2.0-or-later
// docs/deployment.md's table of settings, generated from the settings table.
#pragma once

#include <string>

namespace rfbsim::manager {

/// The Markdown table of every setting: key (as the file names it), default and meaning, one row each, in the
/// table's order. docs/deployment.md holds it between the markers kSettingsDocsBegin and kSettingsDocsEnd.
std::string settings_markdown();

inline constexpr const char* kSettingsDocsBegin =
    "<!-- settings: generated from manager/config/settings_table.cpp; the test \"the docs' settings table is the "
    "declared one\" checks it -->";
inline constexpr const char* kSettingsDocsEnd = "<!-- end of settings -->";

}  // namespace rfbsim::manager
