// SPDX-License-Identifier: GPL-2.0-or-later
// read_small_file: a record file's bytes (session.json, manager.json) read whole, or none. The tools look into
// such files before any strict reader does (which host, which condition), and never read a huge one into memory.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace rfbsim::tools {

/// The most of a session.json the tools read (a few kB in practice; anything larger is not one).
inline constexpr std::uintmax_t kMaxSessionJsonBytes = 4 * 1024 * 1024;

/// A regular file's bytes, or none when it is missing, not a regular file, unreadable or over `limit` bytes.
/// Never throws.
std::optional<std::string> read_small_file(const std::filesystem::path& file, std::uintmax_t limit);

}  // namespace rfbsim::tools
