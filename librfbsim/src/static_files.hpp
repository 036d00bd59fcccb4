// SPDX-License-Identifier: GPL-2.0-or-later
// Pure helpers for serving a static web root: safe path resolution, MIME types, response heads.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace rfbsim::detail {

/// Maps a URL path (not yet percent-decoded) to a file under `root`. "/" and directories map to their
/// index.html. Returns nothing for malformed escapes, "..", backslashes or anything leaving the root.
std::optional<std::filesystem::path> resolve_static_path(const std::filesystem::path& root,
                                                         std::string_view url_path);

/// The Content-Type for a file name, by extension; application/octet-stream when unknown.
std::string_view mime_type_for(const std::filesystem::path& file);

/// A complete response head (status line, standard headers, blank line) for a body of `body_bytes`.
std::string response_head(int status, std::string_view content_type, std::size_t body_bytes);

/// The reason phrase for the status codes the server uses.
std::string_view reason_phrase(int status);

}  // namespace rfbsim::detail
