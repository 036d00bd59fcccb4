// SPDX-License-Identifier: GPL-2.0-or-later
// A scratch folder for the file-loading fuzz targets (the loaders take paths, not text): made once per
// process with a small valid map in it (room.yaml naming room.pgm, 4 x 4 m, a wall all round), removed
// at exit. Inputs are written over one file in it.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace rfbsim::fuzz {

class ScratchFiles {
 public:
  /// The process's scratch folder, made on first use.
  static const ScratchFiles& get() {
    static const ScratchFiles scratch;
    return scratch;
  }

  /// Writes `bytes` to `name` in the folder (replacing it) and returns its path.
  [[nodiscard]] std::filesystem::path write(const std::string& name, std::string_view bytes) const {
    const std::filesystem::path path = dir_ / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
  }

  ~ScratchFiles() {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  ScratchFiles(const ScratchFiles&) = delete;
  ScratchFiles& operator=(const ScratchFiles&) = delete;

 private:
  ScratchFiles() {
    std::string pattern = (std::filesystem::temp_directory_path() / "rfbsim_fuzz_XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      std::perror("rfbsim fuzz: mkdtemp");
      std::abort();
    }
    dir_ = pattern;
    // 40 x 40 cells of 0.1 m: black walls two cells thick round a free (light grey) room.
    std::string pgm = "P5\n40 40\n255\n";
    for (int row = 0; row < 40; ++row) {
      for (int col = 0; col < 40; ++col) {
        const bool wall = row < 2 || row >= 38 || col < 2 || col >= 38;
        pgm.push_back(static_cast<char>(wall ? 0 : 254));
      }
    }
    (void)write("room.pgm", pgm);
    (void)write("room.yaml",
                "image: room.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  }

  std::filesystem::path dir_;
};

}  // namespace rfbsim::fuzz
