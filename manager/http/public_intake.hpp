// SPDX-License-Identifier: GPL-2.0-or-later
// PublicIntake: how connections come in on the public port. The manager's own accept loop instead of
// websocketpp's, which accepts again at once after an error and so spins on EMFILE, and knows nothing of
// per-address caps; the caps themselves; and the address a connection counts as (the peer, or the participant
// a trusted front end names). A template over the websocketpp server type, used on the I/O thread only.
// Compiled as C++17 (websocketpp 0.8.2 does not build as C++20 with g++ 12).
#pragma once

#include <sys/resource.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "admin/metrics.hpp"
#include "config/config.hpp"
#include "http/accept_pause.hpp"
#include "http/client_address.hpp"
#include "http/connection_limits.hpp"
#include "rfbsim/log.hpp"

namespace rfbsim::manager {

namespace intake_detail {

// Descriptors kept free of public connections for the manager itself: the index, logs, and per live session
// its relays' upstream sockets, its ready pipe and its spawn.
constexpr std::size_t kReservedDescriptors = 64;
constexpr std::size_t kDescriptorsPerSession = 8;
// How often a refusal at accept is logged at most: a flood must not become a flood of log lines.
constexpr auto kRefusalLogInterval = std::chrono::seconds(10);

// Public connections allowed at once: the configured cap, or what the descriptor limit leaves after the
// manager's own needs.
inline std::size_t total_connection_cap(const ManagerConfig& config) {
  if (config.abuse.connections_total > 0) return static_cast<std::size_t>(config.abuse.connections_total);
  rlimit limit{};
  if (::getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return 4096;
  const std::size_t reserved =
      kReservedDescriptors + kDescriptorsPerSession * static_cast<std::size_t>(config.max_sessions);
  const auto available = static_cast<std::size_t>(limit.rlim_cur);
  return available > reserved + 16 ? available - reserved : 16;
}

inline std::vector<AddressRange> parse_trusted(const std::vector<std::string>& entries) {
  std::vector<AddressRange> ranges;
  for (const std::string& entry : entries) {
    if (const auto range = parse_address_range(entry)) ranges.push_back(*range);
  }
  return ranges;
}

}  // namespace intake_detail

template <typename Server>
class PublicIntake {
 public:
  using ConnectionPtr = typename Server::connection_ptr;

  PublicIntake(boost::asio::io_context& io, Server& server, const ManagerConfig& config, Metrics& metrics)
      : server_(server),
        metrics_(metrics),
        limits_(static_cast<std::size_t>(config.abuse.connections_per_address),
                intake_detail::total_connection_cap(config)),
        trusted_proxies_(intake_detail::parse_trusted(config.trusted_proxies)),
        pause_(io) {}

  /// Starts accepting on the server's listening socket.
  void start() {
    running_ = true;
    accept_next();
  }
  /// Accepts nothing more (the caller stops the server's listening).
  void stop() {
    running_ = false;
    pause_.cancel();
  }

  /// The address limits and logs use: the peer, or the participant a trusted front end names; an IPv6
  /// address as its /64 (limit_key).
  std::string client_address_of(const ConnectionPtr& con) { return abuse_key(participant_address_of(con)); }

  /// The key a participant's whole address (participant_address_of) counts under in the abuse limits.
  static std::string abuse_key(const std::string& participant) {
    return participant.empty() ? "unknown" : limit_key(participant);
  }

  /// The participant's whole address (not its /64): the peer, or the participant a trusted front end names in
  /// X-Forwarded-For; its keyed hash goes into the session index. "" when the socket is gone.
  std::string participant_address_of(const ConnectionPtr& con) {
    const std::string peer = peer_address_of(con);
    if (peer.empty()) return "";
    return client_address(peer, con->get_request_header("X-Forwarded-For"), trusted_proxies_);
  }

  /// The participant a trusted front end names in X-Forwarded-For, for the PROXY line the relay sends its
  /// session; "" when the peer itself is the participant (or the socket is gone).
  std::string forwarded_participant_of(const ConnectionPtr& con) {
    const std::string peer = peer_address_of(con);
    if (peer.empty()) return "";
    const std::string named = client_address(peer, con->get_request_header("X-Forwarded-For"), trusted_proxies_);
    return named == client_address(peer, "", trusted_proxies_) ? "" : named;
  }

  /// Public connections open now, and from how many addresses (for /metrics).
  std::size_t open_total() const { return limits_.open_total(); }
  std::size_t addresses() const { return limits_.addresses(); }

 private:
  // The socket's peer as text, "" when the socket is gone.
  static std::string peer_address_of(const ConnectionPtr& con) {
    boost::system::error_code ec;
    const auto remote = con->get_raw_socket().lowest_layer().remote_endpoint(ec);
    return ec ? std::string() : remote.address().to_string();
  }

  void accept_next() {
    if (!running_) return;
    ConnectionPtr con = server_.get_connection();
    if (!con) {
      pause("cannot make a connection object");
      return;
    }
    websocketpp::lib::error_code ec;
    server_.async_accept(con, [this, con](const websocketpp::lib::error_code& accept_ec) { accepted(con, accept_ec); },
                         ec);
    if (ec) pause(ec.message());
  }

  void pause(const std::string& why) {
    metrics_.count_accept_error();
    if (!paused_) {
      rfbsim::log::warn("manager", "accepting connections failed (%s); pausing %lld ms between tries", why.c_str(),
                        static_cast<long long>(kAcceptPause.count()));
    }
    paused_ = true;
    pause_.expires_after(kAcceptPause);
    pause_.async_wait([this](const boost::system::error_code& ec) {
      if (!ec) accept_next();
    });
  }

  void accepted(const ConnectionPtr& con, const websocketpp::lib::error_code& ec) {
    if (ec) {
      websocketpp::lib::error_code ignored;
      con->terminate(ignored);
      if (ec == websocketpp::error::operation_canceled || !running_) return;
      pause(ec.message());  // EMFILE and the like: the next accept would fail at once too
      return;
    }
    if (paused_) {
      rfbsim::log::info("manager", "accepting connections again");
      paused_ = false;
    }
    admit(con);
    accept_next();
  }

  // Counts the connection against its address's cap and the total, or closes it at once. A trusted front
  // end carries many participants on one address: it counts in the total only.
  void admit(const ConnectionPtr& con) {
    boost::system::error_code ec;
    auto& socket = con->get_raw_socket().lowest_layer();
    const auto remote = socket.remote_endpoint(ec);
    if (ec) {
      socket.close(ec);
      return;
    }
    const std::string peer = remote.address().to_string();
    const auto parsed = parse_address(peer);
    const bool trusted = parsed && std::any_of(trusted_proxies_.begin(), trusted_proxies_.end(),
                                               [&](const AddressRange& range) { return range_contains(range, *parsed); });
    const std::string key = trusted ? std::string("trusted proxy") : limit_key(peer);
    const bool allowed = trusted ? limits_.try_open_uncapped(key) : limits_.try_open(key);
    if (!allowed) {
      metrics_.count_rejection(Rejection::kConnectionLimit);
      const auto now = std::chrono::steady_clock::now();
      if (now - last_refusal_log_ >= intake_detail::kRefusalLogInterval) {
        last_refusal_log_ = now;
        rfbsim::log::limited(rfbsim::log::Level::kWarn, "connection-cap", "manager",
                             "refused connections over the cap (%zu open, %zu from %s)", limits_.open_total(),
                             limits_.open(key), key.c_str());
      }
      socket.close(ec);
      return;
    }
    // Released when websocketpp is done with the connection, whichever way it ends.
    con->set_termination_handler([this, key](ConnectionPtr) { limits_.closed(key); });
    con->start();
  }

  Server& server_;
  Metrics& metrics_;
  ConnectionLimits limits_;
  std::vector<AddressRange> trusted_proxies_;
  boost::asio::steady_timer pause_;
  bool running_ = false;
  bool paused_ = false;
  std::chrono::steady_clock::time_point last_refusal_log_{};
};

}  // namespace rfbsim::manager
