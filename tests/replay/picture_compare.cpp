// SPDX-License-Identifier: GPL-2.0-or-later
// Picture comparison: MAD and PSNR, and frames decoded from sim_replay's video.
#include "picture_compare.hpp"

#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "sim_process.hpp"

namespace rfbsim::test {

double mean_abs_difference(const Pixels& a, const Pixels& b) {
  REQUIRE(a.size() == b.size());
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += std::abs(int{a[i]} - int{b[i]});
  return sum / static_cast<double>(a.size());
}

double psnr(const Pixels& a, const Pixels& b) {
  REQUIRE(a.size() == b.size());
  double squares = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = int{a[i]} - int{b[i]};
    squares += d * d;
  }
  const double mse = squares / static_cast<double>(a.size());
  return mse == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(255.0 * 255.0 / mse);
}

bool matches(const Pixels& a, const Pixels& b, Tolerance tolerance) {
  return mean_abs_difference(a, b) < tolerance.max_mad && psnr(a, b) > tolerance.min_psnr;
}

Pixels rgb_of(const FrameView& frame) {
  Pixels out;
  out.reserve(static_cast<std::size_t>(frame.width * frame.height * 3));
  for (int y = 0; y < frame.height; ++y) {
    const std::uint8_t* row = frame.row(y);
    for (int x = 0; x < frame.width; ++x) out.insert(out.end(), row + x * 4, row + x * 4 + 3);
  }
  return out;
}

std::vector<Pixels> decoded_frames(const std::filesystem::path& video, const std::vector<std::uint64_t>& indices,
                                   int width, int height, const std::filesystem::path& raw) {
  std::string select;
  for (const std::uint64_t index : indices) {
    select += (select.empty() ? "eq(n\\," : "+eq(n\\,") + std::to_string(index) + ")";
  }
  const ExitResult result = run_to_exit(
      RFBSIM_FFMPEG,
      {"-v", "error", "-y", "-i", video.string(), "-vf",
       "select=" + select + ",scale=in_color_matrix=bt709:in_range=limited:flags=accurate_rnd+full_chroma_int",
       "-vsync", "0", "-f", "rawvideo", "-pix_fmt", "rgb24", raw.string()},
      std::chrono::seconds(120));
  INFO(result.output);
  REQUIRE(WIFEXITED(result.status));
  REQUIRE(WEXITSTATUS(result.status) == 0);
  std::ifstream in(raw, std::ios::binary);
  const Pixels bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::size_t size = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3;
  REQUIRE(bytes.size() == size * indices.size());
  std::vector<Pixels> frames;
  for (std::size_t i = 0; i < indices.size(); ++i) {
    frames.emplace_back(bytes.begin() + static_cast<std::ptrdiff_t>(i * size),
                        bytes.begin() + static_cast<std::ptrdiff_t>((i + 1) * size));
  }
  return frames;
}

}  // namespace rfbsim::test
