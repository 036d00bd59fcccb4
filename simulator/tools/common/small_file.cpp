// SPDX-License-Identifier: GPL-2.0-or-later
// read_small_file: a small file read whole.
#include "small_file.hpp"

#include <fstream>
#include <sstream>

namespace rfbsim::tools {

std::optional<std::string> read_small_file(const std::filesystem::path& file, std::uintmax_t limit) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec || size > limit) return std::nullopt;
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) return std::nullopt;
  return bytes.str();
}

}  // namespace rfbsim::tools
