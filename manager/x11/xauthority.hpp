// SPDX-License-Identifier: GPL-2.0-or-later
// A per-session Xauthority file: one MIT-MAGIC-COOKIE-1 entry that matches any display (FamilyWild, empty
// address and display number), so it is written before Xvnc has picked its display number. Xvnc reads it
// (-auth) and the session's program presents it (XAUTHORITY); a client without the cookie is refused.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace rfbsim::x11 {

/// The cookie's size in bytes (what xauth generates for MIT-MAGIC-COOKIE-1).
constexpr std::size_t kCookieBytes = 16;

/// An MIT-MAGIC-COOKIE-1 secret.
using Cookie = std::array<std::uint8_t, kCookieBytes>;

/// The bytes of one Xauthority entry for `cookie`: family 0xFFFF (FamilyWild), an empty address, an empty
/// display number, the name "MIT-MAGIC-COOKIE-1" and the cookie, each field after a big-endian 16-bit length.
/// Pure.
std::string xauthority_entry(const Cookie& cookie);

/// A fresh cookie from the kernel's random source (getrandom). Throws std::runtime_error when it has none.
Cookie random_cookie();

/// Writes xauthority_entry(cookie) as the whole file `path`, mode 0600: into a new file beside it (created
/// exclusively), then renamed over `path`, so that a reader never sees half a file and a link or file
/// already at `path` is replaced, never followed. Throws std::runtime_error naming the path and the cause.
void write_xauthority(const std::string& path, const Cookie& cookie);

}  // namespace rfbsim::x11
