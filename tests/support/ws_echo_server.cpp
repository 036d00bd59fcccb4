// SPDX-License-Identifier: GPL-2.0-or-later
// WsEchoServer over websocketpp's asio server (plain or TLS) on one I/O thread; what other threads read
// sits behind one mutex, and what they ask for crosses to the I/O thread by post().
// Compiled as C++17 (websocketpp 0.8.2 does not build as C++20 with g++ 12).
#include "ws_echo_server.hpp"

#include <condition_variable>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <websocketpp/config/asio.hpp>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace rfbsim::test {

// What every endpoint flavour shares, read from any thread.
struct WsEchoServer::Impl {
  virtual ~Impl() = default;
  virtual void close_all(int code, const std::string& reason) = 0;

  int port = 0;
  mutable std::mutex mutex;
  mutable std::condition_variable changed;
  std::size_t opened = 0;  // guarded by mutex, like everything below
  std::size_t open_now = 0;
  std::string last_origin;
  std::string last_resource;

  template <typename Edit>
  void update(Edit edit) {
    {
      std::lock_guard lock(mutex);
      edit();
    }
    changed.notify_all();
  }
};

namespace {

namespace asio = boost::asio;

template <typename Config, bool kTls>
class EchoServer final : public WsEchoServer::Impl {
 public:
  using Endpoint = websocketpp::server<Config>;
  using MessagePtr = typename Endpoint::message_ptr;
  using Handle = websocketpp::connection_hdl;

  explicit EchoServer(WsEchoServerOptions options) : options_(std::move(options)) {
    endpoint_.clear_access_channels(websocketpp::log::alevel::all);
    endpoint_.clear_error_channels(websocketpp::log::elevel::all);
    endpoint_.init_asio();
    if constexpr (kTls) {
      // Load the files once, here, so that a bad path throws from the constructor.
      context_ = websocketpp::lib::make_shared<asio::ssl::context>(asio::ssl::context::tls_server);
      boost::system::error_code ec;
      context_->use_certificate_chain_file(options_.cert_pem, ec);
      if (!ec) context_->use_private_key_file(options_.key_pem, asio::ssl::context::pem, ec);
      if (ec) throw std::runtime_error("WsEchoServer: cannot load " + options_.cert_pem + ": " + ec.message());
      endpoint_.set_tls_init_handler([this](Handle) { return context_; });
    }

    // Handlers run on the I/O thread.
    endpoint_.set_validate_handler([this](Handle hdl) {
      const auto connection = endpoint_.get_con_from_hdl(hdl);
      update([&] {
        last_origin = connection->get_request_header("Origin");
        last_resource = connection->get_resource();
      });
      if (options_.reject_status != 0) {
        connection->set_status(static_cast<websocketpp::http::status_code::value>(options_.reject_status));
        return false;
      }
      for (const std::string& offered : connection->get_requested_subprotocols()) {
        if (offered == "binary") connection->select_subprotocol(offered);
      }
      return true;
    });
    endpoint_.set_open_handler([this](Handle hdl) {
      open_.insert(hdl);
      update([&] {
        ++opened;
        ++open_now;
      });
    });
    endpoint_.set_close_handler([this](Handle hdl) { forget(hdl); });
    endpoint_.set_fail_handler([this](Handle hdl) { forget(hdl); });
    endpoint_.set_message_handler([this](Handle hdl, MessagePtr message) {
      websocketpp::lib::error_code ec;
      endpoint_.send(hdl, message->get_payload(), message->get_opcode(), ec);
    });

    // Listen before the thread starts, so that port() is known at once.
    websocketpp::lib::error_code ec;
    endpoint_.listen(asio::ip::tcp::endpoint(asio::ip::address_v4::loopback(), 0), ec);
    if (!ec) endpoint_.start_accept(ec);
    if (ec) throw std::runtime_error("WsEchoServer: cannot listen on 127.0.0.1: " + ec.message());
    boost::system::error_code asio_ec;  // this call takes Asio's error type, not websocketpp's
    port = endpoint_.get_local_endpoint(asio_ec).port();
    if (asio_ec) throw std::runtime_error("WsEchoServer: no local port: " + asio_ec.message());
    io_ = std::thread([this] { endpoint_.run(); });
  }

  ~EchoServer() override {
    endpoint_.stop();
    if (io_.joinable()) io_.join();
  }

  void close_all(int code, const std::string& reason) override {
    asio::post(endpoint_.get_io_service(), [this, code, reason] {
      for (const Handle& hdl : open_) {
        websocketpp::lib::error_code ec;
        endpoint_.close(hdl, static_cast<websocketpp::close::status::value>(code), reason, ec);
      }
    });
  }

 private:
  void forget(Handle hdl) {
    if (open_.erase(hdl) == 0) return;  // a failed handshake was never counted as open
    update([&] { --open_now; });
  }

  const WsEchoServerOptions options_;
  websocketpp::lib::shared_ptr<asio::ssl::context> context_;  // wss only
  Endpoint endpoint_;
  std::set<Handle, std::owner_less<Handle>> open_;  // I/O thread only
  std::thread io_;
};

}  // namespace

WsEchoServer::WsEchoServer(WsEchoServerOptions options) {
  if (options.cert_pem.empty() != options.key_pem.empty()) {
    throw std::invalid_argument("WsEchoServer: give both cert_pem and key_pem, or neither");
  }
  if (options.cert_pem.empty()) {
    impl_ = std::make_unique<EchoServer<websocketpp::config::asio, false>>(std::move(options));
  } else {
    impl_ = std::make_unique<EchoServer<websocketpp::config::asio_tls, true>>(std::move(options));
  }
}

WsEchoServer::~WsEchoServer() = default;

int WsEchoServer::port() const { return impl_->port; }

std::size_t WsEchoServer::opened() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->opened;
}

std::size_t WsEchoServer::open_now() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->open_now;
}

std::string WsEchoServer::last_origin() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->last_origin;
}

std::string WsEchoServer::last_resource() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->last_resource;
}

bool WsEchoServer::wait_opened(std::size_t count, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(impl_->mutex);
  return impl_->changed.wait_for(lock, timeout, [&] { return impl_->opened >= count; });
}

void WsEchoServer::close_all(int code, const std::string& reason) { impl_->close_all(code, reason); }

bool WsEchoServer::wait_all_closed(std::chrono::milliseconds timeout) const {
  std::unique_lock lock(impl_->mutex);
  return impl_->changed.wait_for(lock, timeout, [&] { return impl_->open_now == 0; });
}

}  // namespace rfbsim::test
