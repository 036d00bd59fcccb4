// SPDX-License-Identifier: GPL-2.0-or-later
// WsTestClient over websocketpp's asio client: one I/O thread runs the endpoint; the test thread
// waits on a condition variable for the handshake, for received bytes and for the close.
// Compiled as C++17 (websocketpp 0.8.2 does not build as C++20 with g++ 12).
#include "ws_test_client.hpp"

#include <condition_variable>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

namespace rfbsim::test {

namespace {
using Endpoint = websocketpp::client<websocketpp::config::asio_client>;
enum class State { kConnecting, kOpen, kFailed, kClosed };
}  // namespace

struct WsTestClient::Impl {
  Endpoint endpoint;
  websocketpp::connection_hdl handle;
  std::thread io;

  mutable std::mutex mutex;
  std::condition_variable changed;
  State state = State::kConnecting;  // guarded by mutex, like everything below
  std::string failure;
  std::string subprotocol;
  std::deque<std::uint8_t> received;
  std::uint64_t binary = 0;
  std::uint64_t text = 0;
  int remote_close_code = -1;  // the code in the server's close frame; -1 before one arrived

  template <typename Predicate>
  bool wait(std::unique_lock<std::mutex>& lock, std::chrono::milliseconds timeout, Predicate predicate) {
    return changed.wait_for(lock, timeout, predicate);
  }

  void set_state(State next) {
    {
      std::lock_guard lock(mutex);
      // A close after a failure stays a failure; nothing leaves kClosed.
      if (state == State::kFailed || state == State::kClosed) return;
      state = next;
    }
    changed.notify_all();
  }

  // Runs `work` on the I/O thread, where websocketpp expects connection calls.
  template <typename Work>
  void post(Work work) {
    boost::asio::post(endpoint.get_io_service(), std::move(work));
  }

  // Stops the endpoint if it still runs and joins the I/O thread.
  void stop_and_join() {
    if (!io.joinable()) return;
    endpoint.stop();
    io.join();
  }
};

WsTestClient::WsTestClient(int port, const std::string& path, const std::string& origin,
                           const std::string& subprotocol, std::chrono::milliseconds timeout)
    : impl_(std::make_unique<Impl>()) {
  Impl& self = *impl_;
  self.endpoint.clear_access_channels(websocketpp::log::alevel::all);
  self.endpoint.clear_error_channels(websocketpp::log::elevel::all);
  self.endpoint.init_asio();

  // Handlers run on the I/O thread and only record what happened.
  self.endpoint.set_open_handler([&self](websocketpp::connection_hdl hdl) {
    {
      std::lock_guard lock(self.mutex);
      // websocketpp's client does not record the accepted subprotocol; read it from the response.
      self.subprotocol = self.endpoint.get_con_from_hdl(hdl)->get_response_header("Sec-WebSocket-Protocol");
    }
    self.set_state(State::kOpen);
  });
  self.endpoint.set_fail_handler([&self](websocketpp::connection_hdl hdl) {
    const auto connection = self.endpoint.get_con_from_hdl(hdl);
    {
      std::lock_guard lock(self.mutex);
      self.failure = connection->get_ec().message() + " (HTTP status " +
                     std::to_string(static_cast<int>(connection->get_response_code())) + ")";
    }
    self.set_state(State::kFailed);
  });
  self.endpoint.set_close_handler([&self](websocketpp::connection_hdl hdl) {
    {
      std::lock_guard lock(self.mutex);
      const auto connection = self.endpoint.get_con_from_hdl(hdl);
      // websocketpp reports "no status" (1005) or "abnormal" (1006) when no close frame arrived.
      self.remote_close_code = static_cast<int>(connection->get_remote_close_code());
    }
    self.set_state(State::kClosed);
  });
  self.endpoint.set_message_handler([&self](websocketpp::connection_hdl, Endpoint::message_ptr message) {
    {
      std::lock_guard lock(self.mutex);
      if (message->get_opcode() == websocketpp::frame::opcode::binary) {
        const std::string& payload = message->get_payload();
        self.received.insert(self.received.end(), payload.begin(), payload.end());
        ++self.binary;
      } else {
        ++self.text;
      }
    }
    self.changed.notify_all();
  });

  // Prepare the request: libvncserver insists on Host (from the URI) and Origin.
  websocketpp::lib::error_code ec;
  const std::string uri = "ws://127.0.0.1:" + std::to_string(port) + path;
  const auto connection = self.endpoint.get_connection(uri, ec);
  if (ec) throw std::runtime_error("WebSocket URI " + uri + ": " + ec.message());
  connection->replace_header("Origin", origin);
  if (!subprotocol.empty()) connection->add_subprotocol(subprotocol);
  self.handle = connection->get_handle();
  self.endpoint.connect(connection);
  self.io = std::thread([&self] { self.endpoint.run(); });

  // Wait for the opening handshake to succeed or fail.
  std::unique_lock lock(self.mutex);
  const bool settled = self.wait(lock, timeout, [&self] { return self.state != State::kConnecting; });
  const State state = self.state;
  const std::string failure = self.failure;
  lock.unlock();
  if (settled && state == State::kOpen) return;
  self.stop_and_join();
  throw std::runtime_error("WebSocket handshake with " + uri + " " +
                           (settled ? "failed: " + (failure.empty() ? std::string("closed") : failure)
                                    : std::string("timed out")));
}

WsTestClient::~WsTestClient() {
  if (open()) close();
  impl_->stop_and_join();
}

bool WsTestClient::send_binary(const std::vector<std::uint8_t>& bytes) {
  if (!open()) return false;
  auto message = std::make_shared<std::vector<std::uint8_t>>(bytes);
  Impl& self = *impl_;
  self.post([&self, message] {
    websocketpp::lib::error_code ec;
    self.endpoint.send(self.handle, message->data(), message->size(), websocketpp::frame::opcode::binary, ec);
  });
  return true;
}

bool WsTestClient::read_exact(std::size_t count, std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout) {
  Impl& self = *impl_;
  std::unique_lock lock(self.mutex);
  const bool enough = self.wait(lock, timeout, [&] {
    return self.received.size() >= count || self.state == State::kClosed || self.state == State::kFailed;
  });
  if (!enough || self.received.size() < count) return false;
  const auto end = self.received.begin() + static_cast<std::ptrdiff_t>(count);
  out.assign(self.received.begin(), end);
  self.received.erase(self.received.begin(), end);
  return true;
}

std::string WsTestClient::subprotocol() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->subprotocol;
}

std::uint64_t WsTestClient::binary_messages() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->binary;
}

std::uint64_t WsTestClient::text_messages() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->text;
}

bool WsTestClient::open() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->state == State::kOpen;
}

void WsTestClient::close(std::chrono::milliseconds timeout) {
  Impl& self = *impl_;
  self.post([&self] {
    websocketpp::lib::error_code ec;
    self.endpoint.close(self.handle, websocketpp::close::status::going_away, "test done", ec);
  });
  std::unique_lock lock(self.mutex);
  self.wait(lock, timeout, [&self] { return self.state != State::kOpen; });
}

int WsTestClient::remote_close_code() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->remote_close_code;
}

}  // namespace rfbsim::test
