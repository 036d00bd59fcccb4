// SPDX-License-Identifier: GPL-2.0-or-later
// What the fuzz targets share: the libFuzzer entry point's declaration and an invariant check that aborts,
// so that a broken invariant is a crash libFuzzer keeps (and the corpus replay under ctest fails on).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

/// libFuzzer's entry point: each target defines it; runs one input, returns 0.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace rfbsim::fuzz {

/// Aborts with `what` when `ok` is false: a parser broke one of its own promises.
inline void check(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
  std::abort();
}

/// The input as text (the parsers take bytes as std::string_view).
inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace rfbsim::fuzz
