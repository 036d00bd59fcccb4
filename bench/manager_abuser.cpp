// SPDX-License-Identifier: GPL-2.0-or-later
// The abusive client's two loops; see manager_abuser.hpp.
#include "manager_abuser.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <stdexcept>
#include <vector>

namespace rfbsim::bench {

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// A connection's source is fixed before connect(); IP_BIND_ADDRESS_NO_PORT leaves the port to connect(),
// which can then reuse ports across destinations instead of running out of them at bind().
int socket_from(std::uint32_t from, int flags) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | flags, 0);
  if (fd < 0) return -1;
  const int on = 1;
  ::setsockopt(fd, IPPROTO_IP, IP_BIND_ADDRESS_NO_PORT, &on, sizeof on);
  sockaddr_in source{};
  source.sin_family = AF_INET;
  source.sin_addr.s_addr = from;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&source), sizeof source) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

sockaddr_in manager_address(int port) {
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return to;
}

// The status of an HTTP answer's first line ("HTTP/1.1 429 ..."); -1 when there is none.
int status_of(const std::string& answer) {
  if (answer.rfind("HTTP/1.", 0) != 0 || answer.size() < 12) return -1;
  return std::atoi(answer.c_str() + 9);
}

// One held connection.
struct Slot {
  int fd = -1;
  bool connecting = false;
  Clock::time_point since;      // connect() called
  Clock::time_point reopen_at;  // when closed: open again from then on
};

}  // namespace

Abuser::Abuser(AbuserOptions options) : options_(std::move(options)) {
  in_addr parsed{};
  if (::inet_pton(AF_INET, options_.from.c_str(), &parsed) != 1) {
    throw std::invalid_argument("abuser source address " + options_.from + " is not an IPv4 address");
  }
  from_ = parsed.s_addr;
  half_open_thread_ = std::thread([this] { hold_half_open(); });
  storm_thread_ = std::thread([this] { storm(); });
}

Abuser::~Abuser() { stop(); }

void Abuser::stop() {
  stopping_ = true;
  if (half_open_thread_.joinable()) half_open_thread_.join();
  if (storm_thread_.joinable()) storm_thread_.join();
}

AbuserCounts Abuser::counts() const {
  AbuserCounts c;
  c.connects = connects_.load();
  c.connect_errors = connect_errors_.load();
  c.closed_by_server = closed_by_server_.load();
  c.open_now = open_now_.load();
  c.open_peak = open_peak_.load();
  c.storm_requests = storm_requests_.load();
  const std::lock_guard lock(status_mutex_);
  c.storm_status = storm_status_;
  return c;
}

void Abuser::hold_half_open() {
  // Half a request: the head never ends, so the server waits for the rest until its handshake timeout.
  static const std::string kHalfRequest = "GET /s/idle/ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n";
  const sockaddr_in to = manager_address(options_.port);
  const int epoll_fd = ::epoll_create1(EPOLL_CLOEXEC);
  if (epoll_fd < 0) return;
  std::vector<Slot> slots(static_cast<std::size_t>(options_.half_open));

  const auto close_slot = [&](Slot& slot) {
    ::close(slot.fd);  // also takes it out of the epoll set
    slot.fd = -1;
    slot.connecting = false;
    slot.reopen_at = Clock::now() + options_.reopen_after;
  };
  const auto established = [&](Slot& slot, std::size_t index, bool registered) {
    slot.connecting = false;
    ::send(slot.fd, kHalfRequest.data(), kHalfRequest.size(), MSG_NOSIGNAL);
    epoll_event event{};
    event.events = EPOLLIN | EPOLLRDHUP;
    event.data.u64 = index;
    ::epoll_ctl(epoll_fd, registered ? EPOLL_CTL_MOD : EPOLL_CTL_ADD, slot.fd, &event);
    ++connects_;
    const std::uint64_t open = ++open_now_;
    if (open > open_peak_.load()) open_peak_ = open;
  };

  std::vector<epoll_event> events(256);
  while (!stopping_) {
    // Open what is closed and due; drop connects that hang (a full accept queue drops SYNs).
    const auto now = Clock::now();
    for (std::size_t i = 0; i < slots.size(); ++i) {
      Slot& slot = slots[i];
      if (slot.fd >= 0) {
        if (slot.connecting && now - slot.since > options_.connect_timeout) {
          ++connect_errors_;
          close_slot(slot);
        }
        continue;
      }
      if (now < slot.reopen_at) continue;
      slot.fd = socket_from(from_, SOCK_NONBLOCK);
      if (slot.fd < 0) {
        ++connect_errors_;
        slot.reopen_at = now + options_.reopen_after;
        continue;
      }
      slot.since = now;
      if (::connect(slot.fd, reinterpret_cast<const sockaddr*>(&to), sizeof to) == 0) {
        established(slot, i, false);
      } else if (errno == EINPROGRESS) {
        slot.connecting = true;
        epoll_event event{};
        event.events = EPOLLOUT | EPOLLRDHUP;
        event.data.u64 = i;
        ::epoll_ctl(epoll_fd, EPOLL_CTL_ADD, slot.fd, &event);
      } else {
        ++connect_errors_;
        close_slot(slot);
      }
    }

    // Connects that completed, and held connections the manager answered or closed.
    const int ready = ::epoll_wait(epoll_fd, events.data(), static_cast<int>(events.size()), 50);
    for (int e = 0; e < ready; ++e) {
      const std::size_t index = events[static_cast<std::size_t>(e)].data.u64;
      const std::uint32_t what = events[static_cast<std::size_t>(e)].events;
      Slot& slot = slots[index];
      if (slot.fd < 0) continue;
      if (slot.connecting) {
        int error = 0;
        socklen_t length = sizeof error;
        ::getsockopt(slot.fd, SOL_SOCKET, SO_ERROR, &error, &length);
        if (error != 0 || (what & (EPOLLERR | EPOLLHUP)) != 0) {
          ++connect_errors_;
          close_slot(slot);
        } else if ((what & EPOLLOUT) != 0) {
          established(slot, index, true);
        }
        continue;
      }
      // Read whatever came (an error page, say) until the socket is drained or closed.
      char buffer[4096];
      for (;;) {
        const ssize_t got = ::recv(slot.fd, buffer, sizeof buffer, 0);
        if (got > 0) continue;
        if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
        ++closed_by_server_;
        --open_now_;
        close_slot(slot);
        break;
      }
    }
  }
  for (Slot& slot : slots) {
    if (slot.fd >= 0) ::close(slot.fd);
  }
  open_now_ = 0;
  ::close(epoll_fd);
}

void Abuser::storm() {
  const sockaddr_in to = manager_address(options_.port);
  const auto pause = options_.storm_per_second > 0 ? milliseconds(1000 / options_.storm_per_second) : milliseconds(0);
  auto next = Clock::now();
  for (std::uint64_t n = 0; !stopping_; ++n) {
    if (pause.count() > 0) {
      std::this_thread::sleep_until(next);
      next += pause;
    }
    ++storm_requests_;
    int status = -1;
    const int fd = socket_from(from_, 0);
    if (fd >= 0) {
      // Timeouts keep a stop() prompt: a send or receive (and connect) gives up after a second.
      const timeval limit{1, 0};
      ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
      ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof limit);
      if (::connect(fd, reinterpret_cast<const sockaddr*>(&to), sizeof to) == 0) {
        const std::string request = "GET /start?uid=storm-" + std::to_string(::getpid()) + "-" + std::to_string(n) +
                                    "&scenario=" + options_.scenario +
                                    " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
        std::string answer;
        if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(request.size())) {
          char buffer[4096];
          ssize_t got = 0;
          while (answer.size() < 16 && (got = ::recv(fd, buffer, sizeof buffer, 0)) > 0) answer.append(buffer, static_cast<std::size_t>(got));
        }
        status = status_of(answer);
      }
      ::close(fd);
    }
    if (status < 0 && pause.count() == 0) {
      // Refused outright (out of ports, say): a short breath so this thread does not spin on one error.
      std::this_thread::sleep_for(milliseconds(1));
    }
    const std::lock_guard lock(status_mutex_);
    ++storm_status_[status];
  }
}

}  // namespace rfbsim::bench
