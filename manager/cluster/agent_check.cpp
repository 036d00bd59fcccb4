// SPDX-License-Identifier: GPL-2.0-or-later
// HAProxy agent-check: the status line and the tiny server that writes it.
#include "cluster/agent_check.hpp"

#include <algorithm>
#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "http/accept_pause.hpp"

namespace rfbsim::manager {

namespace {

namespace asio = boost::asio;

// How long a peer may keep a connection open after our line, and how much it may send meanwhile.
constexpr auto kLingerLimit = std::chrono::seconds(2);
constexpr std::size_t kMaxPeerBytes = 4096;

}  // namespace

std::string agent_status_line(const AgentLoad& load) {
  if (load.draining || load.shutting_down || load.max_slots <= 0 || load.free_slots <= 0) return "drain\n";
  const int free_slots = std::min(load.free_slots, load.max_slots);
  // HAProxy scales the server's configured weight by this share; 0% would mean "no new traffic", which a host
  // with a free slot does want, so the least is 1%.
  const long percent = std::lround(100.0 * free_slots / load.max_slots);
  return "up ready " + std::to_string(std::max(1L, percent)) + "%\n";
}

struct AgentCheckServer::State : std::enable_shared_from_this<AgentCheckServer::State> {
  State(asio::io_context& io, std::function<AgentLoad()> load_fn)
      : acceptor(io), pause(io), load(std::move(load_fn)) {}

  void accept() {
    if (!open) return;
    acceptor.async_accept([self = shared_from_this()](const boost::system::error_code& ec, asio::ip::tcp::socket peer) {
      if (!self->open) return;
      if (ec) {
        self->pause.expires_after(kAcceptPause);
        self->pause.async_wait([self](const boost::system::error_code& wait_ec) {
          if (!wait_ec) self->accept();
        });
        return;
      }
      self->answer(std::move(peer));
      self->accept();
    });
  }

  // One line, then the end of our side. What the peer sent (HAProxy's agent-send, or anything) is read and
  // dropped until it closes too: closing with unread bytes would reset the connection, and a reset may
  // discard our line before the peer reads it. A peer that keeps the connection open loses it after a while.
  void answer(asio::ip::tcp::socket peer) {
    auto connection = std::make_shared<Connection>(std::move(peer), acceptor.get_executor());
    connection->line = agent_status_line(load());
    asio::async_write(connection->socket, asio::buffer(connection->line),
                      [connection](const boost::system::error_code& ec, std::size_t) {
                        if (ec) {
                          connection->close();
                          return;
                        }
                        boost::system::error_code ignored;
                        connection->socket.shutdown(asio::ip::tcp::socket::shutdown_send, ignored);
                        connection->timer.expires_after(kLingerLimit);
                        connection->timer.async_wait([connection](const boost::system::error_code& wait_ec) {
                          if (!wait_ec) connection->close();
                        });
                        connection->drain();
                      });
  }

  struct Connection : std::enable_shared_from_this<Connection> {
    Connection(asio::ip::tcp::socket peer, const asio::any_io_executor& executor)
        : socket(std::move(peer)), timer(executor) {}

    void drain() {
      socket.async_read_some(asio::buffer(scratch), [self = shared_from_this()](const boost::system::error_code& ec,
                                                                                 std::size_t size) {
        self->read_total += size;
        if (ec || self->read_total > kMaxPeerBytes) {
          self->close();
          return;
        }
        self->drain();
      });
    }

    void close() {
      boost::system::error_code ignored;
      timer.cancel();
      socket.close(ignored);
    }

    asio::ip::tcp::socket socket;
    asio::steady_timer timer;
    std::string line;
    std::array<char, 256> scratch{};
    std::size_t read_total = 0;
  };

  asio::ip::tcp::acceptor acceptor;
  asio::steady_timer pause;
  std::function<AgentLoad()> load;
  bool open = true;
};

AgentCheckServer::AgentCheckServer(asio::io_context& io, const std::string& address, int port,
                                   std::function<AgentLoad()> load)
    : state_(std::make_shared<State>(io, std::move(load))) {
  boost::system::error_code ec;
  const auto ip = asio::ip::make_address_v4(address, ec);
  if (ec) throw std::runtime_error("agent check: bad address " + address);
  const asio::ip::tcp::endpoint endpoint(ip, static_cast<unsigned short>(port));
  auto& acceptor = state_->acceptor;
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    throw std::runtime_error("agent check: cannot listen on " + address + ":" + std::to_string(port) + ": " +
                             ec.message());
  }
  state_->accept();
}

AgentCheckServer::~AgentCheckServer() { stop(); }

int AgentCheckServer::port() const {
  boost::system::error_code ec;
  const auto endpoint = state_->acceptor.local_endpoint(ec);
  return ec ? 0 : endpoint.port();
}

void AgentCheckServer::stop() {
  state_->open = false;
  boost::system::error_code ignored;
  state_->pause.cancel();
  state_->acceptor.close(ignored);
}

}  // namespace rfbsim::manager
