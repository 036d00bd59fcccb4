// SPDX-License-Identifier: GPL-2.0-or-later
#include "http/page_files.hpp"

#include <fstream>
#include <sstream>

namespace rfbsim::manager {

std::optional<std::string> read_page_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

std::optional<std::string> admin_page_file(const std::string& route_file) {
  const std::string file = route_file.empty() ? "admin.html" : route_file;
  if (file != "admin.html" && file != "admin.js") return std::nullopt;
  return file;
}

}  // namespace rfbsim::manager
