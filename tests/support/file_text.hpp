// SPDX-License-Identifier: GPL-2.0-or-later
// file_text: a file's whole content, for tests that check what a program wrote. Header-only.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace rfbsim::test {

/// The whole content of `file` ("" when it cannot be read).
inline std::string file_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace rfbsim::test
