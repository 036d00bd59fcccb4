// SPDX-License-Identifier: GPL-2.0-or-later
// Random tokens and seeds.
#include "admission/tokens.hpp"

#include <openssl/rand.h>

#include <stdexcept>

namespace rfbsim::manager {

namespace {

void random_bytes(unsigned char* out, int count) {
  if (RAND_bytes(out, count) != 1) throw std::runtime_error("the random number generator failed");
}

}  // namespace

std::string new_session_token() {
  unsigned char bytes[16];
  random_bytes(bytes, sizeof bytes);
  static const char* const kHex = "0123456789abcdef";
  std::string token;
  for (const unsigned char byte : bytes) {
    token.push_back(kHex[byte >> 4]);
    token.push_back(kHex[byte & 0xf]);
  }
  return token;
}

std::uint64_t new_seed() {
  unsigned char bytes[4];
  random_bytes(bytes, sizeof bytes);
  return (std::uint64_t{bytes[0]} << 24) | (std::uint64_t{bytes[1]} << 16) | (std::uint64_t{bytes[2]} << 8) |
         std::uint64_t{bytes[3]};
}

}  // namespace rfbsim::manager
