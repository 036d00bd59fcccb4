// SPDX-License-Identifier: GPL-2.0-or-later
// The settings table of docs/deployment.md, written from the settings table itself: a test compares the two
// (tests/manager/unit/config/settings_docs_test.cpp), so that the docs say what the code does.
#include "config/settings_docs.hpp"

#include "config/settings_table.hpp"

namespace rfbsim::manager {

namespace {

// A table cell must not hold a bare "|".
std::string cell(std::string text) {
  for (std::size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2)) text.replace(at, 1, "\\|");
  return text;
}

// The default column: the default's value as the file writes it, and what the table says of it.
std::string default_cell(const config_table::Setting& setting) {
  const auto shown = setting.kind.show(ManagerConfig{});
  std::string value;
  if (shown && setting.kind.list) {
    value = "`[";
    for (std::size_t i = 0; i < shown->size(); ++i) value += (i == 0 ? "" : ", ") + (*shown)[i];
    value += "]`";
  } else if (shown && !shown->empty()) {
    value = "`" + shown->front() + "`";
  }
  if (setting.default_note.empty()) return value.empty() ? "none" : value;
  return value.empty() ? setting.default_note : value + " (" + setting.default_note + ")";
}

}  // namespace

std::string settings_markdown() {
  std::string table = "| key | default | meaning |\n|---|---|---|\n";
  for (const config_table::Setting& setting : config_table::settings()) {
    std::string meaning = setting.help;
    if (!setting.kind.range.empty()) meaning += " (" + setting.kind.range + ")";
    table += "| `" + config_table::file_name_of(setting.key) + "` | " + cell(default_cell(setting)) + " | " +
             cell(meaning) + " |\n";
  }
  return table;
}

}  // namespace rfbsim::manager
