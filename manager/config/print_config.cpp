// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager --print-config: the settings as the config file that would give them, from the table's own
// reading back of each setting (settings_table.hpp). Written so that reading it back prints it again unchanged:
// an unset setting, whose default depends on others (max_duration_s, fitted to the tasks), stays unset as a
// comment rather than pinned to today's value.
#include <cstdio>
#include <string>

#include "config/config.hpp"
#include "config/settings_table.hpp"

namespace rfbsim::manager {

namespace {

// Characters a value may hold and still be written without quotes: none of YAML's indicators, no space.
bool is_plain_character(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
         ch == '.' || ch == '/' || ch == ':' || ch == '=' || ch == ',' || ch == '+' || ch == '@' || ch == '<' ||
         ch == '>' || ch == '-';
}

// `text` as one YAML scalar that the file reader takes back as the same text.
std::string yaml_scalar(const std::string& text) {
  bool plain = !text.empty() && text.front() != '-' && text.front() != ':' && text.back() != ':';
  for (const char ch : text) plain = plain && is_plain_character(ch);
  // Words YAML reads as null, which yaml-cpp would not hand back as text.
  plain = plain && text != "null" && text != "Null" && text != "NULL";
  if (plain) return text;
  std::string quoted = "\"";
  for (const char ch : text) {
    const auto byte = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      quoted += '\\';
      quoted += ch;
    } else if (byte < 0x20 || byte == 0x7f) {
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\x%02x", byte);
      quoted += escape;
    } else {
      quoted += ch;
    }
  }
  return quoted + "\"";
}

}  // namespace

std::string print_config(const ManagerConfig& config) {
  std::string out =
      "# sim_manager's effective settings: defaults, config files, flags and environment (sim_manager --print-config).\n"
      "# An unset setting is a comment; a secret that is set reads <set>, and its value must come from the\n"
      "# environment or a flag where this file is used.\n";
  std::string open_section;
  for (const config_table::Setting& setting : config_table::settings()) {
    const std::string section = config_table::section_of(setting.key);
    const std::string name = section.empty() ? setting.key : setting.key.substr(section.size() + 1);
    const std::string indent = section.empty() ? "" : "  ";
    if (section != open_section && !section.empty()) {
      // A section of comments only is written as an empty mapping, which the reader takes.
      bool any_set = false;
      for (const config_table::Setting& other : config_table::settings()) {
        any_set = any_set || (config_table::section_of(other.key) == section && other.kind.show(config).has_value());
      }
      out += section + (any_set ? ":\n" : ": {}\n");
    }
    open_section = section;
    const auto shown = setting.kind.show(config);
    if (!shown) {
      const std::string note = config_table::plain_text(setting.default_note);
      out += indent + "# " + name + ":" + (note.empty() ? "" : " (unset: " + note + ")");
      out += "\n";
    } else if (!setting.kind.list) {
      out += indent + name + ": " + yaml_scalar(shown->empty() ? std::string() : shown->front()) + "\n";
    } else if (shown->empty()) {
      out += indent + name + ": []\n";
    } else {
      out += indent + name + ":\n";
      for (const std::string& value : *shown) out += indent + "  - " + yaml_scalar(value) + "\n";
    }
  }
  return out;
}

}  // namespace rfbsim::manager
