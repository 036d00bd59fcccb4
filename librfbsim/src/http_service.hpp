// SPDX-License-Identifier: GPL-2.0-or-later
// HttpService: answers plain HTTP requests on the shared port (the page, its files, JSON routes),
// on a few worker threads of its own so that a slow browser never stalls the RFB thread.
#pragma once

#include <atomic>
#include <deque>
#include <filesystem>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace rfbsim::detail {

struct HttpRequest;

/// What the service serves. Routes are matched exactly on the decoded path.
struct HttpServiceConfig {
  std::filesystem::path web_root;  ///< empty = no static files
  std::map<std::string, std::function<std::string()>> json_routes;
  int max_workers = 16;             ///< connections served at once; more wait for a free worker
  int max_waiting = 256;            ///< connections that may wait; more get 503 at once
  int io_timeout_ms = 5000;         ///< a request head or a write that takes longer is abandoned
};

class HttpService {
 public:
  explicit HttpService(HttpServiceConfig config);
  /// Shuts down every open connection and joins the workers.
  ~HttpService();
  HttpService(const HttpService&) = delete;
  HttpService& operator=(const HttpService&) = delete;

  /// Takes ownership of a connected socket whose first bytes look like HTTP and answers it.
  void serve(int fd);
  /// Requests answered so far.
  [[nodiscard]] std::uint64_t requests() const { return requests_.load(); }

 private:
  struct Worker {
    std::thread thread;
    int fd = -1;
    std::atomic<bool> done{false};
  };
  void run(Worker& worker);
  void serve_one(int fd);
  void respond(int fd, const HttpRequest* request, int parse_status);
  void reap_finished_locked();

  HttpServiceConfig config_;
  std::mutex mutex_;
  std::list<std::unique_ptr<Worker>> workers_;  // guarded by mutex_
  std::deque<int> waiting_;                     // accepted, not yet served; guarded by mutex_
  std::atomic<std::uint64_t> requests_{0};
  std::atomic<bool> stopping_{false};
};

}  // namespace rfbsim::detail
