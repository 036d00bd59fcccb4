// SPDX-License-Identifier: GPL-2.0-or-later
// Client addresses behind trusted proxies.
#include "http/client_address.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <charconv>
#include <cstring>

namespace rfbsim::manager {

namespace {

constexpr std::array<std::uint8_t, 12> kMappedPrefix = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};

std::string_view trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
}

bool is_mapped_v4(const std::array<std::uint8_t, 16>& bytes) {
  return std::memcmp(bytes.data(), kMappedPrefix.data(), kMappedPrefix.size()) == 0;
}

}  // namespace

std::optional<AddressRange> parse_address(std::string_view text) {
  text = trim(text);
  // "[::1]" as some proxies write IPv6.
  if (text.size() >= 2 && text.front() == '[' && text.back() == ']') text = text.substr(1, text.size() - 2);
  if (text.empty() || text.size() > 45) return std::nullopt;
  const std::string copy(text);
  AddressRange out;
  in_addr v4{};
  in6_addr v6{};
  if (::inet_pton(AF_INET, copy.c_str(), &v4) == 1) {
    std::memcpy(out.bytes.data(), kMappedPrefix.data(), kMappedPrefix.size());
    std::memcpy(out.bytes.data() + 12, &v4, 4);
  } else if (::inet_pton(AF_INET6, copy.c_str(), &v6) == 1) {
    std::memcpy(out.bytes.data(), &v6, 16);
  } else {
    return std::nullopt;
  }
  out.prefix = 128;
  return out;
}

std::optional<AddressRange> parse_address_range(std::string_view text) {
  text = trim(text);
  const std::size_t slash = text.find('/');
  auto address = parse_address(text.substr(0, slash));
  if (!address || slash == std::string_view::npos) return address;
  const std::string_view bits = text.substr(slash + 1);
  int prefix = -1;
  const auto [ptr, ec] = std::from_chars(bits.data(), bits.data() + bits.size(), prefix);
  if (bits.empty() || ec != std::errc() || ptr != bits.data() + bits.size()) return std::nullopt;
  // An IPv4 range's prefix counts IPv4 bits; stored as the mapped IPv6 range.
  const bool v4 = text.substr(0, slash).find(':') == std::string_view::npos;
  if (prefix < 0 || prefix > (v4 ? 32 : 128)) return std::nullopt;
  address->prefix = v4 ? 96 + prefix : prefix;
  return address;
}

bool range_contains(const AddressRange& range, const AddressRange& address) {
  int bits = range.prefix;
  for (std::size_t i = 0; i < 16 && bits > 0; ++i, bits -= 8) {
    const std::uint8_t mask = bits >= 8 ? 0xff : static_cast<std::uint8_t>(0xff << (8 - bits));
    if ((range.bytes[i] & mask) != (address.bytes[i] & mask)) return false;
  }
  return true;
}

std::string address_text(const AddressRange& address) {
  char text[INET6_ADDRSTRLEN] = {};
  if (is_mapped_v4(address.bytes)) {
    ::inet_ntop(AF_INET, address.bytes.data() + 12, text, sizeof text);
  } else {
    ::inet_ntop(AF_INET6, address.bytes.data(), text, sizeof text);
  }
  return text;
}

std::string limit_key(std::string_view address) {
  auto parsed = parse_address(address);
  if (!parsed) return std::string(address);
  if (is_mapped_v4(parsed->bytes)) return address_text(*parsed);
  std::fill(parsed->bytes.begin() + 8, parsed->bytes.end(), std::uint8_t{0});
  return address_text(*parsed) + "/64";
}

std::string client_address(std::string_view peer, std::string_view forwarded_for,
                           const std::vector<AddressRange>& trusted) {
  const auto peer_address = parse_address(peer);
  if (!peer_address) return std::string(peer);
  const auto is_trusted = [&](const AddressRange& address) {
    for (const AddressRange& range : trusted) {
      if (range_contains(range, address)) return true;
    }
    return false;
  };
  AddressRange client = *peer_address;
  // Right to left: each trusted hop vouches for the entry before it.
  while (is_trusted(client) && !trim(forwarded_for).empty()) {
    const std::size_t comma = forwarded_for.rfind(',');
    const std::string_view entry = comma == std::string_view::npos ? forwarded_for : forwarded_for.substr(comma + 1);
    const auto parsed = parse_address(entry);
    if (!parsed) break;
    client = *parsed;
    forwarded_for = comma == std::string_view::npos ? std::string_view() : forwarded_for.substr(0, comma);
  }
  return address_text(client);
}

}  // namespace rfbsim::manager
