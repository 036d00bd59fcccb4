// SPDX-License-Identifier: GPL-2.0-or-later
// The after-session copy command's placeholders and retry schedule.
#include "sessions/copy_command.hpp"

#include <algorithm>

namespace rfbsim::manager {

const std::vector<std::string_view> kCopyPlaceholders = {"folder", "folder_name", "uid", "host", "session_id"};

namespace {

bool is_name_char(char ch) { return (ch >= 'a' && ch <= 'z') || ch == '_'; }

// The length of the "{name}" at `at` (braces included), or 0 when the text there is not one: "{", then one
// or more of [a-z_], then "}".
std::size_t placeholder_length(std::string_view text, std::size_t at) {
  if (text[at] != '{') return 0;
  std::size_t end = at + 1;
  while (end < text.size() && is_name_char(text[end])) ++end;
  if (end == at + 1 || end >= text.size() || text[end] != '}') return 0;
  return end - at + 1;
}

const std::string* value_of(std::string_view name, const CopyPlaceholders& values) {
  if (name == "folder") return &values.folder;
  if (name == "folder_name") return &values.folder_name;
  if (name == "uid") return &values.uid;
  if (name == "host") return &values.host;
  if (name == "session_id") return &values.session_id;
  return nullptr;
}

}  // namespace

std::string copy_command_problem(const std::vector<std::string>& command) {
  if (command.empty()) return "";
  if (command.front().empty()) return "after_session_command: the program (its first item) is empty";
  for (std::size_t item = 0; item < command.size(); ++item) {
    const std::string& arg = command[item];
    for (std::size_t i = 0; i < arg.size(); ++i) {
      const std::size_t length = placeholder_length(arg, i);
      if (length == 0) continue;
      const std::string_view name = std::string_view(arg).substr(i + 1, length - 2);
      if (std::find(kCopyPlaceholders.begin(), kCopyPlaceholders.end(), name) == kCopyPlaceholders.end()) {
        std::string known;
        for (const std::string_view k : kCopyPlaceholders) known += (known.empty() ? "{" : " {") + std::string(k) + "}";
        return "after_session_command: unknown placeholder {" + std::string(name) + "} in '" + arg + "' (known: " +
               known + ")";
      }
      // A value at the start of an argument could read as an option: uids may begin with '-' ("-etouch" to
      // rsync names a remote shell). {folder} is an absolute path, so it always begins with '/'.
      if (i == 0 && (item == 0 || name != "folder")) {
        return "after_session_command: '" + arg + "' begins with {" + std::string(name) + "}" +
               (item == 0 ? ", but the program must be fixed"
                          : ": a value such as a uid beginning with '-' would read as an option; put a fixed "
                            "prefix before it (e.g. 'store:/study/{" + std::string(name) + "}')");
      }
      i += length - 1;
    }
  }
  return "";
}

std::vector<std::string> substitute_copy_command(const std::vector<std::string>& command,
                                                 const CopyPlaceholders& values) {
  std::vector<std::string> out;
  out.reserve(command.size());
  for (const std::string& arg : command) {
    // One pass from left to right: what a value brings in is never looked at again.
    std::string text;
    for (std::size_t i = 0; i < arg.size();) {
      const std::size_t length = placeholder_length(arg, i);
      const std::string* value =
          length == 0 ? nullptr : value_of(std::string_view(arg).substr(i + 1, length - 2), values);
      if (value == nullptr) {
        text += arg[i++];
        continue;
      }
      text += *value;
      i += length;
    }
    out.push_back(std::move(text));
  }
  return out;
}

std::chrono::seconds copy_backoff(int failed_tries) {
  if (failed_tries < 1) return std::chrono::seconds(0);
  std::chrono::seconds wait = kCopyFirstBackoff;
  for (int i = 1; i < failed_tries && wait < kCopyMaxBackoff; ++i) wait *= 2;
  return std::min(wait, kCopyMaxBackoff);
}

}  // namespace rfbsim::manager
