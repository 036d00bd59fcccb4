// SPDX-License-Identifier: GPL-2.0-or-later
// PROXY protocol version 1 headers.
#include "proxy_header.hpp"

#include <arpa/inet.h>

#include <vector>

namespace rfbsim::detail {

namespace {

std::vector<std::string_view> split_spaces(std::string_view text) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t space = text.find(' ', start);
    const std::size_t end = space == std::string_view::npos ? text.size() : space;
    parts.push_back(text.substr(start, end - start));
    if (space == std::string_view::npos) break;
    start = space + 1;
  }
  return parts;
}

bool is_port(std::string_view text) {
  if (text.empty() || text.size() > 5) return false;
  unsigned value = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + static_cast<unsigned>(c - '0');
  }
  return value <= 65535 && !(text.size() > 1 && text[0] == '0');
}

bool is_address(std::string_view text, int family) {
  if (text.empty() || text.size() > 45) return false;
  // inet_pton reads a C string: a NUL inside would hide what follows it.
  for (const char c : text) {
    const bool ok = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F') || c == '.' || c == ':';
    if (!ok) return false;
  }
  const std::string copy(text);
  unsigned char bytes[16];
  return ::inet_pton(family, copy.c_str(), bytes) == 1;
}

}  // namespace

ProxyHeader parse_proxy_header(std::string_view first_bytes) {
  // sim_manager's mark on a watch connection, after UNKNOWN (see the header).
  constexpr std::string_view kViewOnlyWord = "view-only";
  ProxyHeader header;
  constexpr std::string_view kSignature = "PROXY ";
  // Every prefix of the signature may still become one; anything else cannot.
  const std::size_t compare = std::min(first_bytes.size(), kSignature.size());
  if (first_bytes.substr(0, compare) != kSignature.substr(0, compare)) {
    header.status = ProxyHeader::Status::Invalid;
    return header;
  }
  const std::size_t end = first_bytes.find("\r\n");
  if (end == std::string_view::npos || end + 2 > kMaxProxyHeaderBytes) {
    header.status = first_bytes.size() >= kMaxProxyHeaderBytes ? ProxyHeader::Status::Invalid
                                                               : ProxyHeader::Status::Incomplete;
    return header;
  }
  header.status = ProxyHeader::Status::Invalid;
  const auto parts = split_spaces(first_bytes.substr(kSignature.size(), end - kSignature.size()));
  if (!parts.empty() && parts[0] == "UNKNOWN") {
    header.status = ProxyHeader::Status::Valid;  // the relay does not know; the rest of the line is ignored
    header.length = end + 2;
    // Only the exact word counts: any other text after UNKNOWN (another relay's) stays a plain UNKNOWN.
    header.view_only = parts.size() == 2 && parts[1] == kViewOnlyWord;
    return header;
  }
  if (parts.size() != 5) return header;
  const int family = parts[0] == "TCP4" ? AF_INET : parts[0] == "TCP6" ? AF_INET6 : -1;
  if (family < 0 || !is_address(parts[1], family) || !is_address(parts[2], family) || !is_port(parts[3]) ||
      !is_port(parts[4])) {
    return header;
  }
  header.status = ProxyHeader::Status::Valid;
  header.length = end + 2;
  header.source = std::string(parts[1]);
  return header;
}

}  // namespace rfbsim::detail
