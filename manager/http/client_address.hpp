// SPDX-License-Identifier: GPL-2.0-or-later
// The participant's address for limits and logs: the socket's peer, or, when the peer is a trusted front end
// (nginx, HAProxy), the address it reports in X-Forwarded-For. Pure: no I/O.
//
// Only trusted peers are believed: anyone else can write any X-Forwarded-For. Of the header's list, the
// rightmost address that is not itself a trusted proxy is the client (each proxy appends the peer it saw,
// so entries to the left of that one came from the client and may be made up).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rfbsim::manager {

/// An IPv4 or IPv6 network: address and prefix length.
struct AddressRange {
  std::array<std::uint8_t, 16> bytes{};  ///< IPv4 as an IPv4-mapped IPv6 address
  int prefix = 128;                       ///< in IPv6 bits (an IPv4 /24 is 96 + 24)
};

/// Parses "10.0.0.1", "10.0.0.0/8", "::1" or "fd00::/8"; nothing for anything else.
std::optional<AddressRange> parse_address_range(std::string_view text);

/// Parses one address (IPv4, IPv6, IPv4-mapped IPv6 as ::ffff:a.b.c.d) as a /32 or /128 range.
std::optional<AddressRange> parse_address(std::string_view text);

/// Whether `address` lies in `range`.
bool range_contains(const AddressRange& range, const AddressRange& address);

/// The canonical text of an address (IPv4 dotted, IPv6 compressed; IPv4-mapped shown as IPv4), so that one
/// machine always counts under one key.
std::string address_text(const AddressRange& address);

/// The key a client counts under in the abuse limits: an IPv4 address as itself, an IPv6 address as its
/// /64 ("2001:db8:1:2::/64"). An ISP hands each subscriber at least a /64, so one machine can draw a fresh
/// IPv6 address per connection from it: counting per address would give it 2^64 allowances. Text that is no
/// address is returned as it is.
std::string limit_key(std::string_view address);

/// The client's address: `peer` (as the socket reports it), unless `peer` is in `trusted` and
/// `forwarded_for` (the X-Forwarded-For header, "" if absent) names one. Unparseable entries stop the walk
/// (the peer's view is kept). Returns canonical text.
std::string client_address(std::string_view peer, std::string_view forwarded_for,
                           const std::vector<AddressRange>& trusted);

}  // namespace rfbsim::manager
