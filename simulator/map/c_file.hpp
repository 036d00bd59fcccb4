// SPDX-License-Identifier: GPL-2.0-or-later
// CFile: a C stdio FILE* that closes itself. The map readers use fopen rather than streams because errno after
// fopen names the cause reliably, and libpng reads from a FILE*.
#pragma once

#include <cstdio>
#include <memory>

namespace rfbsim::sim {

/// Closes a FILE* (the deleter of CFile).
struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

/// An owned FILE*, closed when it goes out of scope; null when fopen failed.
using CFile = std::unique_ptr<std::FILE, FileCloser>;

}  // namespace rfbsim::sim
