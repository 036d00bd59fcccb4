// SPDX-License-Identifier: GPL-2.0-or-later
// The files of the participant's and the admin page, read from the web root for one response each: the
// page is small, and reading it anew lets a researcher update it without restarting the manager.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace rfbsim::manager {

/// A page file's whole content, or nothing when it is missing, unreadable or not a regular file.
std::optional<std::string> read_page_file(const std::filesystem::path& path);

/// The file an /admin route names: /admin is admin.html, /admin/admin.js its script, and nothing else of the
/// web root is reachable there (nothing = 404).
std::optional<std::string> admin_page_file(const std::string& route_file);

}  // namespace rfbsim::manager
