// SPDX-License-Identifier: GPL-2.0-or-later
// HMAC-SHA256 link signatures with OpenSSL.
#include "admission/link_signature.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>

#include <algorithm>
#include <stdexcept>

namespace rfbsim::manager {

std::string canonical_link_text(const QueryParams& params) {
  QueryParams sorted;
  for (const auto& param : params) {
    if (param.first != "sig") sorted.push_back(param);
  }
  std::sort(sorted.begin(), sorted.end());
  std::string text;
  for (const auto& [name, value] : sorted) {
    if (!text.empty()) text += '&';
    text += name + "=" + value;
  }
  return text;
}

std::string hmac_sha256_hex(std::string_view secret, std::string_view text) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  HMAC(EVP_sha256(), secret.data(), static_cast<int>(secret.size()),
       reinterpret_cast<const unsigned char*>(text.data()), text.size(), digest, &length);
  static const char* const kHex = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < length; ++i) {
    hex.push_back(kHex[digest[i] >> 4]);
    hex.push_back(kHex[digest[i] & 0xf]);
  }
  return hex;
}

bool link_signature_valid(const QueryParams& params, std::string_view secret) {
  const auto sig = std::find_if(params.begin(), params.end(), [](const auto& p) { return p.first == "sig"; });
  if (sig == params.end()) return false;
  const std::string expected = hmac_sha256_hex(secret, canonical_link_text(params));
  if (sig->second.size() != expected.size()) return false;
  return CRYPTO_memcmp(sig->second.data(), expected.data(), expected.size()) == 0;
}

std::string sign_query(std::string_view query, std::string_view secret) {
  std::string error;
  const auto params = parse_query(query, error);
  if (!params) throw std::invalid_argument(error);
  for (const auto& param : *params) {
    if (param.first == "sig") throw std::invalid_argument("the query already has a sig");
  }
  std::string out(query);
  if (!out.empty()) out += '&';
  return out + "sig=" + hmac_sha256_hex(secret, canonical_link_text(*params));
}

}  // namespace rfbsim::manager
