// SPDX-License-Identifier: GPL-2.0-or-later
// HttpService: read one request head, answer it, close; a bounded pool of workers, a bounded wait list.
#include "http_service.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "http_request.hpp"
#include "rfbsim/log.hpp"
#include "static_files.hpp"

namespace rfbsim::detail {

namespace {

// Writes everything or gives up at the deadline; the peer may vanish at any point.
bool send_all(int fd, std::string_view bytes, int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (!bytes.empty()) {
    const auto n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      bytes.remove_prefix(static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return false;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd pfd{fd, POLLOUT, 0};
    ::poll(&pfd, 1, static_cast<int>(left.count()));
  }
  return true;
}

std::string error_body(int status, std::string_view detail) {
  return std::to_string(status) + " " + std::string(reason_phrase(status)) + ": " + std::string(detail) + "\n";
}

std::string read_file(const std::filesystem::path& file, bool& ok) {
  std::ifstream in(file, std::ios::binary);
  ok = static_cast<bool>(in);
  if (!ok) return {};
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

}  // namespace

HttpService::HttpService(HttpServiceConfig config) : config_(std::move(config)) {}

HttpService::~HttpService() {
  stopping_ = true;
  std::list<std::unique_ptr<Worker>> workers;
  {
    std::lock_guard lock(mutex_);
    // Wake workers blocked in poll so that they finish promptly.
    for (auto& worker : workers_) {
      if (worker->fd >= 0) ::shutdown(worker->fd, SHUT_RDWR);
    }
    for (const int fd : waiting_) ::close(fd);
    waiting_.clear();
    workers.swap(workers_);
  }
  for (auto& worker : workers) worker->thread.join();
}

void HttpService::reap_finished_locked() {
  for (auto it = workers_.begin(); it != workers_.end();) {
    if ((*it)->done) {
      (*it)->thread.join();
      it = workers_.erase(it);
    } else {
      ++it;
    }
  }
}

void HttpService::serve(int fd) {
  std::lock_guard lock(mutex_);
  reap_finished_locked();
  if (!stopping_ && static_cast<int>(workers_.size()) < config_.max_workers) {
    auto worker = std::make_unique<Worker>();
    worker->fd = fd;
    Worker& ref = *worker;
    workers_.push_back(std::move(worker));
    ref.thread = std::thread([this, &ref] { run(ref); });
    return;
  }
  // A browser loading the page's modules opens connections in bursts; a busy or slow host (a sanitizer
  // build, a loaded server) must make them wait, not fail the page.
  if (!stopping_ && static_cast<int>(waiting_.size()) < config_.max_waiting) {
    waiting_.push_back(fd);
    return;
  }
  const std::string body = error_body(503, "too many requests at once, try again");
  send_all(fd, response_head(503, "text/plain; charset=utf-8", body.size()) + body, 100);
  ::close(fd);
}

void HttpService::run(Worker& worker) {
  for (;;) {
    serve_one(worker.fd);
    // Closed under the lock so that the destructor never shuts down a descriptor number already reused.
    std::lock_guard lock(mutex_);
    ::close(worker.fd);
    worker.fd = -1;
    if (stopping_ || waiting_.empty()) break;
    worker.fd = waiting_.front();
    waiting_.pop_front();
  }
  worker.done = true;
}

void HttpService::serve_one(int fd) {
  std::string received;
  int status = 0;  // 0 = parsed; otherwise the error status to answer
  HttpParseResult parsed;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(config_.io_timeout_ms);
  // Read until the head is complete, invalid, too large or late.
  for (;;) {
    parsed = parse_http_request(received);
    if (parsed.status == HttpParseResult::Status::Complete) break;
    if (parsed.status == HttpParseResult::Status::Invalid) {
      status = received.size() > kMaxHttpHeadBytes ? 431 : 400;
      break;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      status = 408;
      break;
    }
    pollfd pfd{fd, POLLIN, 0};
    if (::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) continue;
    char buffer[4096];
    const auto n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
      status = -1;  // the client left; nobody to answer
      break;
    }
    if (n > 0) received.append(buffer, static_cast<std::size_t>(n));
  }
  if (status < 0) return;
  if (parsed.status == HttpParseResult::Status::Invalid) {
    rfbsim::log::limited(rfbsim::log::Level::kInfo, "bad-http-request", "rfbsim.http", "bad request: %s",
                         parsed.error.c_str());
  }
  respond(fd, status == 0 ? &parsed.request : nullptr, status);
}

void HttpService::respond(int fd, const HttpRequest* request, int parse_status) {
  ++requests_;
  const auto answer = [&](int status, std::string_view type, const std::string& body, bool head_only) {
    const std::string head = response_head(status, type, body.size());
    send_all(fd, head_only ? head : head + body, config_.io_timeout_ms);
  };
  if (request == nullptr) {
    answer(parse_status, "text/plain; charset=utf-8", error_body(parse_status, "malformed request"), false);
    return;
  }
  const bool head_only = request->method == "HEAD";
  if (request->method != "GET" && !head_only) {
    answer(405, "text/plain; charset=utf-8", error_body(405, "only GET and HEAD"), false);
    return;
  }
  if (request->is_websocket_upgrade()) {
    // Only reached when a WebSocket head arrived too slowly to be sniffed; the client retries.
    answer(503, "text/plain; charset=utf-8", error_body(503, "WebSocket handshake too slow"), false);
    return;
  }
  std::string decoded;
  if (!percent_decode_path(request->path, decoded)) {
    answer(400, "text/plain; charset=utf-8", error_body(400, "malformed path"), head_only);
    return;
  }
  if (auto route = config_.json_routes.find(decoded); route != config_.json_routes.end()) {
    answer(200, "application/json", route->second(), head_only);
    return;
  }
  if (config_.web_root.empty()) {
    answer(404, "text/plain; charset=utf-8", error_body(404, "no web page is served here"), head_only);
    return;
  }
  const auto file = resolve_static_path(config_.web_root, request->path);
  if (!file) {
    answer(403, "text/plain; charset=utf-8", error_body(403, "path not allowed"), head_only);
    return;
  }
  std::error_code ec;
  bool ok = std::filesystem::is_regular_file(*file, ec);
  const std::string body = ok ? read_file(*file, ok) : std::string();
  if (!ok) {
    answer(404, "text/plain; charset=utf-8", error_body(404, request->path), head_only);
    return;
  }
  answer(200, mime_type_for(*file), body, head_only);
}

}  // namespace rfbsim::detail
