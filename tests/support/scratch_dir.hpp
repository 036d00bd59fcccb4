// SPDX-License-Identifier: GPL-2.0-or-later
// Test helper: a fresh folder per test, removed with everything in it when the test ends.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace rfbsim::test {

/// A unique folder under the system's temp directory (mkdtemp), removed at scope exit.
class ScratchDir {
 public:
  /// `prefix` starts the folder's name (then six random characters).
  explicit ScratchDir(const std::string& prefix = "rfbsim_test") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed for " + pattern);
    // Canonical, so that it compares equal to what a child's pwd prints even if /tmp is a link.
    dir_ = std::filesystem::canonical(pattern);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return dir_; }
  [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// Writes `text` to `name` and returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream out(dir_ / name, std::ios::binary);
    out << text;
    return path(name);
  }

  /// The whole content of `name` ("" if it does not exist).
  [[nodiscard]] std::string read(const std::string& name) const {
    std::ifstream in(dir_ / name, std::ios::binary | std::ios::ate);
    if (!in) return "";
    std::string text(static_cast<std::size_t>(in.tellg()), '\0');
    in.seekg(0);
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    return text;
  }

 private:
  std::filesystem::path dir_;
};

}  // namespace rfbsim::test
