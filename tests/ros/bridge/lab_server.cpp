// SPDX-License-Identifier: GPL-2.0-or-later
// LabServer over websocketpp's asio server (plain or TLS) on one I/O thread; what the tests read sits
// behind one mutex; sends cross to the I/O thread by post(). Compiled as C++17 (websocketpp 0.8.2).
#include "lab_server.hpp"

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <websocketpp/config/asio.hpp>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace rfbsim::test {

struct LabServer::Impl {
  virtual ~Impl() = default;
  virtual void send_all(const std::string& text) = 0;

  int port = 0;
  mutable std::mutex mutex;
  std::size_t opened = 0;  // guarded by mutex, like everything below
  std::vector<std::string> authorizations;
  std::vector<std::string> received;
  std::size_t pings = 0;
  std::atomic<bool> answer_pings{true};
};

namespace {

namespace asio = boost::asio;

template <typename Config, bool kTls>
class Server final : public LabServer::Impl {
 public:
  using Endpoint = websocketpp::server<Config>;
  using Handle = websocketpp::connection_hdl;

  explicit Server(const LabServerOptions& options) {
    endpoint_.clear_access_channels(websocketpp::log::alevel::all);
    endpoint_.clear_error_channels(websocketpp::log::elevel::all);
    endpoint_.init_asio();
    endpoint_.set_reuse_addr(true);
    if constexpr (kTls) {
      context_ = websocketpp::lib::make_shared<asio::ssl::context>(asio::ssl::context::tls_server);
      boost::system::error_code ec;
      context_->use_certificate_chain_file(options.cert_pem, ec);
      if (!ec) context_->use_private_key_file(options.key_pem, asio::ssl::context::pem, ec);
      if (ec) throw std::runtime_error("LabServer: cannot load " + options.cert_pem + ": " + ec.message());
      endpoint_.set_tls_init_handler([this](Handle) { return context_; });
    }
    endpoint_.set_open_handler([this](Handle hdl) {
      open_.insert(hdl);
      const std::string authorization = endpoint_.get_con_from_hdl(hdl)->get_request_header("Authorization");
      const std::lock_guard lock(mutex);
      ++opened;
      authorizations.push_back(authorization);
    });
    endpoint_.set_ping_handler([this](Handle, std::string) {
      const std::lock_guard lock(mutex);
      ++pings;
      return answer_pings.load();  // true: websocketpp sends the pong
    });
    endpoint_.set_close_handler([this](Handle hdl) { open_.erase(hdl); });
    endpoint_.set_fail_handler([this](Handle hdl) { open_.erase(hdl); });
    endpoint_.set_message_handler([this](Handle, typename Endpoint::message_ptr message) {
      const std::lock_guard lock(mutex);
      received.push_back(message->get_payload());
    });
    websocketpp::lib::error_code ec;
    endpoint_.listen(asio::ip::tcp::endpoint(asio::ip::address_v4::loopback(),
                                             static_cast<unsigned short>(options.port)), ec);
    if (!ec) endpoint_.start_accept(ec);
    if (ec) throw std::runtime_error("LabServer: cannot listen: " + ec.message());
    boost::system::error_code asio_ec;
    port = endpoint_.get_local_endpoint(asio_ec).port();
    io_ = std::thread([this] { endpoint_.run(); });
  }

  ~Server() override {
    endpoint_.stop();
    if (io_.joinable()) io_.join();
  }

  void send_all(const std::string& text) override {
    asio::post(endpoint_.get_io_service(), [this, text] {
      for (const Handle& hdl : open_) {
        websocketpp::lib::error_code ec;
        endpoint_.send(hdl, text, websocketpp::frame::opcode::text, ec);
      }
    });
  }

 private:
  websocketpp::lib::shared_ptr<asio::ssl::context> context_;
  Endpoint endpoint_;
  std::set<Handle, std::owner_less<Handle>> open_;  // I/O thread only
  std::thread io_;
};

}  // namespace

LabServer::LabServer(LabServerOptions options) {
  if (options.cert_pem.empty()) {
    impl_ = std::make_unique<Server<websocketpp::config::asio, false>>(options);
  } else {
    impl_ = std::make_unique<Server<websocketpp::config::asio_tls, true>>(options);
  }
}

LabServer::~LabServer() = default;

int LabServer::port() const { return impl_->port; }

std::size_t LabServer::opened() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->opened;
}

std::vector<std::string> LabServer::authorizations() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->authorizations;
}

std::vector<std::string> LabServer::received() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->received;
}

void LabServer::send_all(const std::string& text) { impl_->send_all(text); }

std::size_t LabServer::pings() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->pings;
}

void LabServer::answer_pings(bool answer) { impl_->answer_pings = answer; }

}  // namespace rfbsim::test
