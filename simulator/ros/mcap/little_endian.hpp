// SPDX-License-Identifier: GPL-2.0-or-later
// Little-endian appends into a byte buffer, shared by the CDR encoder and the MCAP records: both formats are
// little-endian on every host (ROS 2's CDR_LE encapsulation; MCAP spec, "Serialization": fixed-width types).
#pragma once

#include <bit>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace rfbsim::ros {

/// Appends the unsigned integer `v` to `out`, least significant byte first.
template <std::unsigned_integral U>
inline void put_le(std::vector<std::uint8_t>& out, U v) {
  for (std::size_t i = 0; i < sizeof(U); ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

/// Overwrites the 8 bytes at `at` in `out` with `v`, least significant first (a record length known later).
inline void patch_le64(std::vector<std::uint8_t>& out, std::size_t at, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) out[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace rfbsim::ros
