// SPDX-License-Identifier: GPL-2.0-or-later
// TestWsClient: RFC 6455 framing by hand (client frames masked, server frames not), blocking reads with
// poll() deadlines.
#include "test_ws_client.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <stdexcept>

namespace rfbsim::test {

namespace {

int connect_loopback(int port, int receive_buffer) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error("socket failed");
  if (receive_buffer > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    throw std::runtime_error("cannot connect to 127.0.0.1:" + std::to_string(port));
  }
  return fd;
}

void write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t written = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (written <= 0) throw std::runtime_error("send failed");
    bytes.remove_prefix(static_cast<std::size_t>(written));
  }
}

std::string request(int port, const std::string& path, bool upgrade) {
  std::string text = "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n";
  if (upgrade) {
    // The key is any 16 bytes in base64; the test does not check the accept value.
    text += "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
            "Sec-WebSocket-Version: 13\r\n";
  }
  return text + "\r\n";
}

// Reads until the end of the HTTP head; returns the head and leaves what follows in `rest`.
std::string read_head(int fd, std::string& rest) {
  std::string bytes;
  char chunk[4096];
  while (bytes.find("\r\n\r\n") == std::string::npos) {
    pollfd waiting{fd, POLLIN, 0};
    if (::poll(&waiting, 1, 10000) <= 0) return "";
    const ssize_t got = ::recv(fd, chunk, sizeof chunk, 0);
    if (got <= 0) return bytes;
    bytes.append(chunk, static_cast<std::size_t>(got));
  }
  const std::size_t end = bytes.find("\r\n\r\n") + 4;
  rest = bytes.substr(end);
  return bytes.substr(0, end);
}

int status_of(const std::string& head) {
  if (head.size() < 12 || head.compare(0, 5, "HTTP/") != 0) return 0;
  return std::stoi(head.substr(9, 3));
}

}  // namespace

TestWsClient::TestWsClient(int port, const std::string& path, int receive_buffer)
    : fd_(connect_loopback(port, receive_buffer)) {
  write_all(fd_, request(port, path, true));
  const int status = status_of(read_head(fd_, buffer_));
  if (status != 101) {
    ::close(fd_);
    throw std::runtime_error("WebSocket handshake got HTTP " + std::to_string(status));
  }
}

TestWsClient::~TestWsClient() {
  if (fd_ >= 0) ::close(fd_);
}

int TestWsClient::handshake_status(int port, const std::string& path, bool upgrade) {
  const int fd = connect_loopback(port, 0);
  write_all(fd, request(port, path, upgrade));
  std::string rest;
  const int status = status_of(read_head(fd, rest));
  ::close(fd);
  return status;
}

void TestWsClient::send(std::string_view payload, int opcode) {
  std::string frame;
  frame.push_back(static_cast<char>(0x80 | opcode));  // FIN
  const std::uint64_t size = payload.size();
  if (size < 126) {
    frame.push_back(static_cast<char>(0x80 | size));
  } else if (size <= 0xffff) {
    frame.push_back(static_cast<char>(0x80 | 126));
    for (int shift = 8; shift >= 0; shift -= 8) frame.push_back(static_cast<char>((size >> shift) & 0xff));
  } else {
    frame.push_back(static_cast<char>(0x80 | 127));
    for (int shift = 56; shift >= 0; shift -= 8) frame.push_back(static_cast<char>((size >> shift) & 0xff));
  }
  const unsigned char mask[4] = {0x12, 0x34, 0x56, 0x78};
  frame.append(reinterpret_cast<const char*>(mask), 4);
  const std::size_t start = frame.size();
  frame.append(payload);
  for (std::size_t i = start; i < frame.size(); ++i) {
    frame[i] = static_cast<char>(static_cast<unsigned char>(frame[i]) ^ mask[(i - start) % 4]);
  }
  write_all(fd_, frame);
}

bool TestWsClient::fill(std::chrono::steady_clock::time_point deadline) {
  if (ended_) return false;
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
  pollfd waiting{fd_, POLLIN, 0};
  if (left.count() <= 0 || ::poll(&waiting, 1, static_cast<int>(left.count())) <= 0) return false;
  char chunk[65536];
  const ssize_t got = ::recv(fd_, chunk, sizeof chunk, 0);
  if (got <= 0) {
    ended_ = true;
    return false;
  }
  buffer_.append(chunk, static_cast<std::size_t>(got));
  return true;
}

std::optional<WsFrame> TestWsClient::read_frame(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    // Header: 2 bytes, then 0, 2 or 8 bytes of length (server frames carry no mask).
    if (buffer_.size() >= 2) {
      const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(buffer_[i]); };
      std::uint64_t size = byte(1) & 0x7f;
      std::size_t header = 2;
      if (size == 126) header = 4;
      if (size == 127) header = 10;
      if (buffer_.size() >= header) {
        if (header > 2) {
          size = 0;
          for (std::size_t i = 2; i < header; ++i) size = (size << 8) | byte(i);
        }
        if (buffer_.size() >= header + size) {
          WsFrame frame{byte(0) & 0x0f, buffer_.substr(header, size)};
          buffer_.erase(0, header + size);
          if (frame.opcode == 8 && frame.payload.size() >= 2) {
            close_code_ = (static_cast<unsigned char>(frame.payload[0]) << 8) | static_cast<unsigned char>(frame.payload[1]);
          }
          return frame;
        }
      }
    }
    if (!fill(deadline)) return std::nullopt;
  }
}

std::optional<nlohmann::json> TestWsClient::wait_for(const std::function<bool(const nlohmann::json&)>& match,
                                                     std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    const std::optional<WsFrame> frame = read_frame(left);
    if (!frame || frame->opcode == 8) return std::nullopt;
    if (frame->opcode != 1) continue;
    const nlohmann::json value = nlohmann::json::parse(frame->payload, nullptr, false);
    if (!value.is_discarded() && match(value)) return value;
  }
}

}  // namespace rfbsim::test
