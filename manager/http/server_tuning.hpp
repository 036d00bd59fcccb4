// SPDX-License-Identifier: GPL-2.0-or-later
// The public port's websocketpp server settings: quiet logs, bounded handshakes and bodies, and no Nagle.
// Included only by http/frontend.cpp (websocketpp 0.8.2 builds only as C++17).
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <cstddef>
#include <websocketpp/server.hpp>

namespace rfbsim::manager {

/// Sets up `server` on `io` before it listens; `max_message_size` bounds what one WebSocket message may hold.
template <typename Server>
void tune_server(Server& server, boost::asio::io_context& io, std::size_t max_message_size) {
  server.clear_access_channels(websocketpp::log::alevel::all);
  server.clear_error_channels(websocketpp::log::elevel::all);
  server.init_asio(&io);
  server.set_user_agent("rfbsim-manager");
  server.set_reuse_addr(true);
  server.set_listen_backlog(256);
  server.set_open_handshake_timeout(5000);  // a slow or silent client loses its connection, not ours
  server.set_close_handshake_timeout(2000);
  server.set_max_http_body_size(64 * 1024);
  server.set_max_message_size(max_message_size);
  // No Nagle on browser sockets: the relay sends each update's last small piece as it comes, and with
  // Nagle it waited for the browser's delayed ACK (about 50 ms per update, measured by bench_manager).
  // (After accept: websocketpp's socket-init hook runs before the socket is open.)
  server.set_tcp_pre_init_handler([&server](websocketpp::connection_hdl hdl) {
    boost::system::error_code ignored;
    server.get_con_from_hdl(hdl)->get_raw_socket().set_option(boost::asio::ip::tcp::no_delay(true), ignored);
  });
}

}  // namespace rfbsim::manager
