// SPDX-License-Identifier: GPL-2.0-or-later
// Keyed hashes of network addresses and file digests (OpenSSL).
#include "record/digest.hpp"

#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace rfbsim::sim {

namespace {

std::string to_hex(const unsigned char* bytes, unsigned int count) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < count; ++i) {
    hex.push_back(kHex[bytes[i] >> 4]);
    hex.push_back(kHex[bytes[i] & 15]);
  }
  return hex;
}

}  // namespace

std::string address_hash_key() {
  if (const char* key = std::getenv("RFBSIM_ADDRESS_KEY"); key != nullptr && *key != '\0') return key;
  std::string key(32, '\0');
  if (RAND_bytes(reinterpret_cast<unsigned char*>(key.data()), static_cast<int>(key.size())) != 1) {
    throw std::runtime_error("cannot draw a random key for hashing addresses (OpenSSL RAND_bytes failed)");
  }
  return key;
}

std::string hash_address(const std::string& key, const std::string& address) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), reinterpret_cast<const unsigned char*>(address.data()),
       address.size(), digest, &length);
  return to_hex(digest, std::min(length, 8u));
}

std::string hash_uid(const std::string& key, const std::string& uid) { return hash_address(key, "uid:" + uid); }

std::string sha256_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot read it to take its digest");
  const std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  if (!context || EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) != 1) {
    throw std::runtime_error("OpenSSL cannot start a SHA-256 digest");
  }
  char block[65536];
  while (in.read(block, sizeof block) || in.gcount() > 0) {
    EVP_DigestUpdate(context.get(), block, static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw std::runtime_error(file.string() + ": read error while taking its digest");
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(context.get(), digest, &length);
  return to_hex(digest, length);
}

}  // namespace rfbsim::sim
