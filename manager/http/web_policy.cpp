// SPDX-License-Identifier: GPL-2.0-or-later
// Response headers, origin and admin checks.
#include "http/web_policy.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>

#include <cstdio>

namespace rfbsim::manager {

namespace {

bool equal_constant_time(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  return CRYPTO_memcmp(a.data(), b.data(), a.size()) == 0;
}

bool starts_with_ci(std::string_view text, std::string_view prefix) {
  if (text.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    const char a = text[i] >= 'A' && text[i] <= 'Z' ? static_cast<char>(text[i] + 32) : text[i];
    if (a != prefix[i]) return false;
  }
  return true;
}

}  // namespace

Headers page_headers(const std::vector<std::string>& frame_origins) {
  std::string ancestors = "frame-ancestors 'self'";
  for (const std::string& origin : frame_origins) ancestors += " " + origin;
  return {
      {"Content-Security-Policy", ancestors},
      {"Cache-Control", "no-store"},
      {"Referrer-Policy", "no-referrer"},
      {"X-Content-Type-Options", "nosniff"},
  };
}

bool websocket_origin_allowed(std::string_view origin, std::string_view host,
                              const std::vector<std::string>& frame_origins) {
  if (origin.empty()) return true;
  for (const std::string& allowed : frame_origins) {
    if (origin == allowed) return true;
  }
  std::string_view origin_host = origin;
  if (origin_host.rfind("https://", 0) == 0) {
    origin_host.remove_prefix(8);
  } else if (origin_host.rfind("http://", 0) == 0) {
    origin_host.remove_prefix(7);
  } else {
    return false;  // "null" (sandboxed frames, files) and anything odd
  }
  return !host.empty() && origin_host == host;
}

bool admin_authorized(std::string_view authorization, std::string_view token) {
  if (token.empty()) return false;
  if (starts_with_ci(authorization, "bearer ")) return equal_constant_time(authorization.substr(7), token);
  if (!starts_with_ci(authorization, "basic ")) return false;
  const std::string_view encoded = authorization.substr(6);
  if (encoded.empty() || encoded.size() > 1024 || encoded.size() % 4 != 0) return false;
  std::string decoded(encoded.size() / 4 * 3 + 1, '\0');
  const int length = EVP_DecodeBlock(reinterpret_cast<unsigned char*>(decoded.data()),
                                     reinterpret_cast<const unsigned char*>(encoded.data()),
                                     static_cast<int>(encoded.size()));
  if (length < 0) return false;
  // EVP_DecodeBlock counts the padding's zero bytes too; drop them.
  std::size_t size = static_cast<std::size_t>(length);
  if (encoded.back() == '=') --size;
  if (encoded.size() >= 2 && encoded[encoded.size() - 2] == '=') --size;
  decoded.resize(size);
  const std::size_t colon = decoded.find(':');
  if (colon == std::string::npos) return false;
  return equal_constant_time(std::string_view(decoded).substr(colon + 1), token);
}

std::string html_escape(std::string_view text) {
  std::string out;
  for (const char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out.push_back(ch);
    }
  }
  return out;
}

std::string json_escape(std::string_view text) {
  std::string out;
  for (const char ch : text) {
    switch (ch) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(ch)));
          out += escaped;
        } else {
          out.push_back(ch);
        }
    }
  }
  return out;
}

}  // namespace rfbsim::manager
