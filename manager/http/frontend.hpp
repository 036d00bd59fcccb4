// SPDX-License-Identifier: GPL-2.0-or-later
// The manager's one public port: HTTP (or HTTPS) for links, pages, health, metrics and the admin API, and
// WebSocket (or WSS) relayed as raw RFB to each session's loopback port. websocketpp on the manager's
// asio I/O thread; this header names no websocketpp type (websocketpp 0.8 builds only as C++17).
#pragma once

#include <boost/asio/io_context.hpp>
#include <memory>
#include <string>

#include "config/config.hpp"
#include "admin/metrics.hpp"
#include "sessions/supervisor.hpp"

namespace rfbsim::manager {

class Frontend {
 public:
  virtual ~Frontend() = default;
  /// The port actually bound (useful with port 0).
  [[nodiscard]] virtual int port() const = 0;
  /// "http" or "https".
  [[nodiscard]] virtual const char* scheme() const = 0;
  /// Stops accepting and closes every connection (WebSockets with 1001 "server shutting down").
  virtual void stop() = 0;
};

class RegistryClient;

/// Listens on the config's address and port, with TLS when the config names a certificate and key.
/// Registers itself as the supervisor's listener. `registry` (may be null: a single host) decides the home of
/// a uid this host has no session of before /start starts one; it must outlive the frontend. Throws
/// std::runtime_error naming the cause (address in use, unreadable certificate or key).
std::unique_ptr<Frontend> make_frontend(boost::asio::io_context& io, const ManagerConfig& config,
                                        Supervisor& supervisor, Metrics& metrics, const std::string& web_root,
                                        RegistryClient* registry = nullptr);

}  // namespace rfbsim::manager
