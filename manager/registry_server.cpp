// SPDX-License-Identifier: GPL-2.0-or-later
// The uid registry's acceptor: one signed line in, one signed line out, the record committed in between.
#include "registry_server.hpp"

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

#include "uid_registry.hpp"

namespace rfbsim::manager {

namespace {

namespace asio = boost::asio;
using asio::ip::tcp;

// A peer sends its one line at once: a connection still silent after this is dropped.
constexpr auto kReadTimeout = std::chrono::seconds(2);
// Connections served at once; more are closed at accept (a claimer treats that as a peer that is down).
constexpr int kMaxConnections = 64;

long long unix_now() {
  return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

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

RegistryServer::RegistryServer(asio::io_context& io, const std::string& bind_address, int port, std::string secret,
                               const std::string& index_path)
    : io_(io), secret_(std::move(secret)), store_(index_path), acceptor_(io) {
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
  accept();
}

RegistryServer::~RegistryServer() {
  stop();
  pool_.join();  // every record asked for is committed before the index closes
}

void RegistryServer::stop() {
  boost::system::error_code ignored;
  acceptor_.close(ignored);
}

void RegistryServer::record(const std::string& uid, const std::string& host, Recorded done) {
  asio::post(pool_, [this, uid, host, done = std::move(done)]() mutable {
    std::string home;
    try {
      home = store_.claim_uid_home(uid, host, std::chrono::system_clock::now());
    } catch (const std::exception& error) {
      std::fprintf(stderr, "[registry] cannot record the home of uid %s: %s\n", uid.c_str(), error.what());
    }
    asio::post(io_, [done = std::move(done), home] { done(home); });
  });
}

void RegistryServer::accept() {
  acceptor_.async_accept([this](const boost::system::error_code& ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted || !acceptor_.is_open()) return;
    if (!ec) serve(std::move(socket));
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
        const ClaimParse parsed = parse_claim_line(line, secret_, unix_now());
        if (!parsed.claim) {
          std::fprintf(stderr, "[registry] refused a claim: %s\n", parsed.error.c_str());
          answer(connection, error_line(parsed.error));
          return;
        }
        const std::string uid = parsed.claim->uid;
        record(uid, parsed.claim->host, [this, connection, uid](const std::string& home) {
          answer(connection, home.empty() ? error_line("index unavailable") : owner_line(secret_, uid, home));
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
    std::fprintf(stderr, "[registry] warning: %s may be read by other users; chmod 600 it (docs/security.md)\n",
                 path.c_str());
  }
  return secret;
}

}  // namespace rfbsim::manager
