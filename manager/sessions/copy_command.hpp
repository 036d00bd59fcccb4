// SPDX-License-Identifier: GPL-2.0-or-later
// The after-session copy command (after_session_command): its placeholders and its retry schedule. Pure: the
// command is an argument list (never a shell string), and a placeholder's value is one argument's text, so a
// folder or uid can never become a second argument or a shell word.
#pragma once

#include <chrono>
#include <string>
#include <string_view>
#include <vector>

namespace rfbsim::manager {

/// What the placeholders of an after-session command stand for, for one session.
struct CopyPlaceholders {
  std::string folder;       ///< {folder}: the session's folder, absolute
  std::string folder_name;  ///< {folder_name}: its last component ("12-p-01")
  std::string uid;          ///< {uid}: the participant id
  std::string host;         ///< {host}: the manager's host_id
  std::string session_id;   ///< {session_id}: the index row id, decimal
};

/// The placeholder names an after-session command may use, without braces.
extern const std::vector<std::string_view> kCopyPlaceholders;

/// Why `command` cannot be an after-session command ("" when it can): an empty program, or a "{name}" whose
/// name (lower-case letters and '_') is not one of kCopyPlaceholders, e.g. "after_session_command: unknown
/// placeholder {dir} in 'rsync://x/{dir}' (known: {folder} {folder_name} {uid} {host} {session_id})".
/// An empty list is fine: no copy. Other braces ("{a,b}", "{}") are the program's own text.
std::string copy_command_problem(const std::vector<std::string>& command);

/// `command` with every known "{name}" replaced by its value, in one pass (a value's own braces are kept as
/// they are). Call copy_command_problem first: an unknown placeholder is left as it is.
std::vector<std::string> substitute_copy_command(const std::vector<std::string>& command, const CopyPlaceholders& values);

/// The first wait before a failed copy is tried again, and the longest.
inline constexpr std::chrono::seconds kCopyFirstBackoff{5};
inline constexpr std::chrono::seconds kCopyMaxBackoff{300};

/// The wait after the `failed_tries`-th failed try (from 1) before the next: 5 s, then doubling up to 5 min
/// (5, 10, 20, 40, 80, 160, 300, 300 ... s). 0 for failed_tries < 1.
std::chrono::seconds copy_backoff(int failed_tries);

}  // namespace rfbsim::manager
