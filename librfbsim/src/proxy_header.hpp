// SPDX-License-Identifier: GPL-2.0-or-later
// The PROXY protocol's version 1 header (HAProxy's), with which a trusted relay in front of the server
// tells it the real client's address: one line "PROXY TCP4 <src> <dst> <sport> <dport>\r\n" (TCP6 alike,
// or "PROXY UNKNOWN...\r\n"), at most 107 bytes, before the client's own bytes. Pure: no sockets.
// Version 1 lets UNKNOWN carry anything up to CR LF, which receivers ignore; sim_manager uses that room
// for one word of its own, "PROXY UNKNOWN view-only\r\n", marking a researcher's watch connection.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace rfbsim::detail {

/// The longest header version 1 allows, CR LF included.
constexpr std::size_t kMaxProxyHeaderBytes = 107;

struct ProxyHeader {
  enum class Status {
    Incomplete,  ///< no CR LF yet, and not too long: wait for more bytes
    Valid,       ///< a whole header: `length` bytes to consume, `source` the client's address
    Invalid,     ///< not a version 1 header (or too long): refuse the connection
  };
  Status status = Status::Incomplete;
  std::size_t length = 0;  ///< bytes of the header, CR LF included (Valid)
  std::string source;      ///< the source address as written ("203.0.113.5", "2001:db8::1"); "" for UNKNOWN
  bool view_only = false;  ///< the line was exactly "PROXY UNKNOWN view-only": the relay's watcher (Valid)
};

/// Looks at the first bytes a connection sent.
ProxyHeader parse_proxy_header(std::string_view first_bytes);

}  // namespace rfbsim::detail
