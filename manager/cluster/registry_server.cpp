// SPDX-License-Identifier: GPL-2.0-or-later
// The uid registry's acceptor: one signed line in, one signed line out, the state committed in between.
#include "cluster/registry_server.hpp"

#include <sys/stat.h>

#include <boost/asio/read_until.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "admission/unix_time.hpp"
#include "cluster/uid_registry.hpp"
#include "http/accept_pause.hpp"
#include "rfbsim/log.hpp"

namespace rfbsim::manager {

namespace {

namespace asio = boost::asio;
using asio::ip::tcp;

// A peer sends its one line at once: a connection still silent after this is dropped.
constexpr auto kReadTimeout = std::chrono::seconds(2);
// Connections served at once; more are closed at accept (a proposer treats that as a peer that is down).
constexpr int kMaxConnections = 64;

}  // namespace

struct RegistryServer::Connection {
  Connection(tcp::socket s, asio::io_context& io, std::shared_ptr<int> open)
      : socket(std::move(s)), timer(io), open_count(std::move(open)) {
    ++*open_count;
  }
  ~Connection() { --*open_count; }
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  tcp::socket socket;
  asio::steady_timer timer;
  asio::streambuf buffer{kMaxRegistryLine};  // a longer line fails the read: "line too long"
  std::string reply;
  std::shared_ptr<int> open_count;
};

RegistryServer::RegistryServer(asio::io_context& io, const std::string& bind_address, int port, std::string key,
                               std::string self, std::vector<ClusterPeer> peers, const std::string& index_path)
    : io_(io),
      key_(std::move(key)),
      self_(std::move(self)),
      peers_(std::move(peers)),
      store_(index_path),
      acceptor_(io),
      accept_pause_(io) {
  boost::system::error_code ec;
  const auto address = asio::ip::make_address_v4(bind_address, ec);
  if (ec) throw std::runtime_error("registry: '" + bind_address + "' is not a numeric IPv4 address");
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(port));
  acceptor_.open(endpoint.protocol(), ec);
  if (!ec) acceptor_.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor_.bind(endpoint, ec);
  if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    throw std::runtime_error("registry: cannot listen on " + bind_address + ":" + std::to_string(port) + ": " +
                             ec.message());
  }
  port_ = acceptor_.local_endpoint().port();
  initial_counter_ = store_.max_uid_ballot_counter();  // before the pool's thread uses store_
  accept();
}

RegistryServer::~RegistryServer() {
  stop();
  pool_.join();  // every record asked for is committed before the index closes
}

void RegistryServer::stop() {
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  accept_pause_.cancel();
}

void RegistryServer::handle(const RegistryMessage& request, Answered done) {
  asio::post(pool_, [this, request, done = std::move(done)]() mutable {
    std::optional<RegistryMessage> answer;
    try {
      // One thread owns this table (pool_), so read, rule and write need no lock of their own.
      AcceptorState state = store_.uid_acceptor(request.uid);
      const AcceptorState before = state;
      RegistryMessage reply = acceptor_answer(state, request);
      if (state != before) store_.set_uid_acceptor(request.uid, state, std::chrono::system_clock::now());
      answer = std::move(reply);
    } catch (const std::exception& error) {
      rfbsim::log::warn("registry", "cannot keep the acceptor state of uid %s: %s", request.uid.c_str(), error.what());
    }
    asio::post(io_, [done = std::move(done), answer = std::move(answer)] { done(answer); });
  });
}

void RegistryServer::accept() {
  acceptor_.async_accept([this](const boost::system::error_code& ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted || !acceptor_.is_open()) return;
    if (ec) {
      accept_pause_.expires_after(kAcceptPause);
      accept_pause_.async_wait([this](const boost::system::error_code& wait_ec) {
        if (!wait_ec && acceptor_.is_open()) accept();
      });
      return;
    }
    serve(std::move(socket));
    accept();
  });
}

void RegistryServer::serve(tcp::socket socket) {
  if (*open_ >= kMaxConnections) {
    boost::system::error_code ignored;
    socket.close(ignored);
    return;
  }
  auto connection = std::make_shared<Connection>(std::move(socket), io_, open_);
  // One timer for the whole exchange: a peer that stalls anywhere loses its connection.
  connection->timer.expires_after(kReadTimeout);
  connection->timer.async_wait([connection](const boost::system::error_code& ec) {
    if (ec) return;
    boost::system::error_code ignored;
    connection->socket.close(ignored);
  });
  asio::async_read_until(
      connection->socket, connection->buffer, '\n',
      [this, connection](const boost::system::error_code& ec, std::size_t length) {
        if (ec == asio::error::not_found) {
          answer(connection, error_line("line too long"));
          return;
        }
        if (ec) return;  // closed or timed out: nothing to answer
        const auto data = connection->buffer.data();
        const std::string line(asio::buffers_begin(data), asio::buffers_begin(data) + static_cast<long>(length) - 1);
        const MessageParse parsed = parse_message(line, key_);
        const std::string problem =
            parsed.message ? request_problem(*parsed.message, self_, peers_, unix_seconds_now()) : parsed.error;
        if (!problem.empty()) {
          // A bad hmac from a real peer means another secret or another cluster_peers list on that host.
          rfbsim::log::limited(rfbsim::log::Level::kWarn, "registry-refused", "registry", "refused a request: %s%s",
                               problem.c_str(),
                               problem == "bad hmac" ? " (another cluster_secret_file or cluster_peers list?)" : "");
          answer(connection, error_line(problem));
          return;
        }
        handle(*parsed.message, [this, connection](const std::optional<RegistryMessage>& reply) {
          answer(connection, reply ? format_message(key_, *reply) : error_line("index unavailable"));
        });
      });
}

void RegistryServer::answer(const std::shared_ptr<Connection>& connection, std::string line) {
  connection->reply = std::move(line);
  asio::async_write(connection->socket, asio::buffer(connection->reply),
                    [connection](const boost::system::error_code&, std::size_t) {
                      boost::system::error_code ignored;
                      connection->socket.shutdown(tcp::socket::shutdown_both, ignored);
                      connection->socket.close(ignored);
                      connection->timer.cancel();
                    });
}

std::string read_cluster_secret(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cluster_secret_file " + path + ": cannot read the file");
  std::ostringstream content;
  content << in.rdbuf();
  std::string secret = content.str();
  // A trailing newline (echo, an editor) is not part of the secret: every host must read the same bytes.
  while (!secret.empty() && (secret.back() == '\n' || secret.back() == '\r' || secret.back() == ' ' ||
                             secret.back() == '\t')) {
    secret.pop_back();
  }
  if (secret.size() < 16) {
    throw std::runtime_error("cluster_secret_file " + path + ": needs at least 16 bytes of secret");
  }
  struct stat status{};
  if (::stat(path.c_str(), &status) == 0 && (status.st_mode & 077) != 0) {
    rfbsim::log::warn("registry", "warning: %s may be read by other users; chmod 600 it (docs/security.md)",
                      path.c_str());
  }
  return secret;
}

}  // namespace rfbsim::manager
