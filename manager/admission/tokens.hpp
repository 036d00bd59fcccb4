// SPDX-License-Identifier: GPL-2.0-or-later
// Unguessable session tokens and drawn seeds, from OpenSSL's CSPRNG.
#pragma once

#include <cstdint>
#include <string>

namespace rfbsim::manager {

/// 128 random bits as 32 lower-case hex digits. Throws std::runtime_error if the CSPRNG fails.
std::string new_session_token();

/// A random seed for a link that gave none, 0..2^32-1 (short enough to read out and type).
std::uint64_t new_seed();

}  // namespace rfbsim::manager
