// SPDX-License-Identifier: GPL-2.0-or-later
// LinkEmulator: one I/O thread runs a ppoll loop over a wake-up pipe, the listening socket and both sockets
// of every relayed connection. Each pass moves chunks from the bottleneck queues into the pipes when they
// have been serialized, writes what is due to the receivers, then sleeps until the next chunk is due or a
// socket is ready, and reads from the senders that still have room.
#include "link_emulator.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

namespace rfbsim::test {
namespace {

using Clock = std::chrono::steady_clock;
using TimePoint = Clock::time_point;

constexpr std::size_t kMaxChunk = 16 * 1024;   // bytes per read without a cap, and the most with one
constexpr std::size_t kMinCappedChunk = 1448;  // one Ethernet-sized TCP segment
constexpr double kCappedChunkSeconds = 0.002;  // with a cap, a chunk is about this long on the wire
constexpr int kSocketBuffer = 64 * 1024;       // SO_RCVBUF and SO_SNDBUF of every emulator socket
constexpr int kMaxSegment = 1460;              // TCP_MAXSEG: Ethernet's, 1448 payload bytes with timestamps
constexpr int kReadsPerPass = 16;              // per socket, so one busy sender cannot starve the rest
constexpr auto kAcceptBackoff = std::chrono::milliseconds(10);  // after running out of descriptors

// A socket or pipe end, closed on destruction.
class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() { reset(); }
  Fd(Fd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  Fd& operator=(Fd&& other) noexcept {
    if (this != &other) {
      reset();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  [[nodiscard]] int get() const { return fd_; }
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

void validate(const LinkProfile& p) {
  if (p.one_way_delay_down.count() < 0 || p.one_way_delay_up.count() < 0)
    throw std::invalid_argument("LinkProfile: a one-way delay is negative");
  if (!std::isfinite(p.down_mbit) || !std::isfinite(p.up_mbit) || p.down_mbit < 0 || p.up_mbit < 0)
    throw std::invalid_argument("LinkProfile: a rate is negative or not finite");
  if (p.bottleneck_queue_bytes == 0) throw std::invalid_argument("LinkProfile: bottleneck_queue_bytes is 0");
  if (p.window_bytes == 0) throw std::invalid_argument("LinkProfile: window_bytes is 0");
}

// TCP_NODELAY and small buffers, so the emulator's own socket buffers hide little of the link; an
// Ethernet-sized MSS (set before listen or connect, it is what the peer's kernel is told), so the peers
// send segments and size their own buffers as on a real path rather than for loopback's 64 KiB MTU.
void tune_socket(int fd) {
  const int one = 1;
  const int size = kSocketBuffer;
  const int mss = kMaxSegment;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, sizeof size);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &size, sizeof size);
  ::setsockopt(fd, IPPROTO_TCP, TCP_MAXSEG, &mss, sizeof mss);
}

// Time to put `bytes` on a link of `mbit` Mbit/s (zero without a cap).
Clock::duration serialization_time(std::size_t bytes, double mbit) {
  if (mbit <= 0) return Clock::duration::zero();
  const std::chrono::duration<double> seconds(static_cast<double>(bytes) * 8.0 / (mbit * 1e6));
  return std::chrono::round<Clock::duration>(seconds);
}

// Bytes per read: 16 KiB without a cap, about 2 ms of the rate with one.
std::size_t chunk_size(double mbit) {
  if (mbit <= 0) return kMaxChunk;
  const double bytes = mbit * 1e6 / 8.0 * kCappedChunkSeconds;
  return std::clamp(static_cast<std::size_t>(std::llround(bytes)), kMinCappedChunk, kMaxChunk);
}

// Reads from `source` while `lane` has room, kReadsPerPass times at most; an end of stream or a read
// error ends the lane's input.
void read_into(LinkLane& lane, int source, const LinkLane::Settings& settings) {
  for (int i = 0; i < kReadsPerPass; ++i) {
    const std::size_t size = lane.read_size(settings);
    if (size == 0) return;
    std::vector<char> bytes(size);
    const ssize_t n = ::recv(source, bytes.data(), size, MSG_DONTWAIT);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    if (n <= 0) {
      lane.push_end(Clock::now());
      return;
    }
    bytes.resize(static_cast<std::size_t>(n));
    lane.push(std::move(bytes), Clock::now());
  }
}

// Writes what is due to `sink`, then the end of stream (shutdown) when that is due; false when the
// receiver is gone (a write failed other than for a full buffer).
bool deliver(LinkLane& lane, int sink, TimePoint now) {
  for (;;) {
    if (lane.end_due(now)) {
      ::shutdown(sink, SHUT_WR);  // fails harmlessly when the receiver has gone already
      lane.end_delivered();
      return true;
    }
    const std::span<const char> bytes = lane.due(now);
    if (bytes.empty()) return true;
    const ssize_t n = ::send(sink, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK;
    lane.consume(static_cast<std::size_t>(n));
  }
}

// Totals and peaks for one direction, kept by the I/O thread.
struct Tally {
  std::uint64_t read = 0;       // by connections already closed
  std::uint64_t delivered = 0;  // by connections already closed
  std::size_t peak_queued = 0;  // since the last publication
  Clock::duration peak_delay{};

  void add_peaks(LinkLane& lane) {
    const auto [queued, delay] = lane.take_peaks();
    peak_queued = std::max(peak_queued, queued);
    peak_delay = std::max(peak_delay, delay);
  }
};

// A relayed connection: the client's socket, the one to the target, and the two directions between them.
struct Connection {
  Fd client;
  Fd upstream;
  bool connecting = true;      // the connect to the target is in progress
  bool dead = false;           // to be closed before the next wait
  LinkLane up;                 // client -> upstream
  LinkLane down;               // upstream -> client
  std::size_t poll_index = 0;  // of the client's pollfd; the upstream's follows it
};

}  // namespace

LinkLane::Settings LinkLane::up(const LinkProfile& p) {
  return {p.one_way_delay_up, p.up_mbit, p.bottleneck_queue_bytes, p.window_bytes};
}

LinkLane::Settings LinkLane::down(const LinkProfile& p) {
  return {p.one_way_delay_down, p.down_mbit, p.bottleneck_queue_bytes, p.window_bytes};
}

std::size_t LinkLane::read_size(const Settings& settings) const {
  // Without a cap, chunks wait in the queue only until the next pass, so they count against the window.
  const bool capped = settings.mbit > 0;
  const std::size_t held = pipe_bytes_ + (capped ? 0 : queued_bytes_);
  if (input_ended_ || held >= settings.window_bytes) return 0;
  std::size_t room = settings.window_bytes - held;
  if (capped) room = queued_bytes_ >= settings.queue_bytes ? 0 : std::min(room, settings.queue_bytes - queued_bytes_);
  return std::min(room, chunk_size(settings.mbit));
}

void LinkLane::push(std::vector<char> bytes, TimePoint arrived) {
  queued_bytes_ += bytes.size();
  bytes_read_ += bytes.size();
  peak_queued_ = std::max(peak_queued_, queued_bytes_);
  queue_.push_back(Chunk{std::move(bytes), false, arrived, false, {}, {}, 0});
}

void LinkLane::push_end(TimePoint arrived) {
  input_ended_ = true;
  queue_.push_back(Chunk{{}, true, arrived, false, {}, {}, 0});
}

void LinkLane::advance(const Settings& settings, TimePoint now) {
  while (!queue_.empty()) {
    // The head starts serializing when it arrived or when the link came free, at the rate now in force.
    Chunk& head = queue_.front();
    if (!head.started) {
      head.leaves = std::max(head.arrived, link_free_) + serialization_time(head.bytes.size(), settings.mbit);
      head.started = true;
    }
    if (head.leaves > now) return;
    // Through the bottleneck: into the pipe, due one delay later.
    link_free_ = head.leaves;
    head.due = head.leaves + settings.delay;
    peak_delay_ = std::max(peak_delay_, head.leaves - head.arrived);
    queued_bytes_ -= head.bytes.size();
    pipe_bytes_ += head.bytes.size();
    pipe_.push_back(std::move(head));
    queue_.pop_front();
  }
}

std::span<const char> LinkLane::due(TimePoint now) const {
  if (pipe_.empty() || pipe_.front().end || pipe_.front().due > now) return {};
  const Chunk& head = pipe_.front();
  return std::span<const char>(head.bytes).subspan(head.written);
}

void LinkLane::consume(std::size_t n) {
  Chunk& head = pipe_.front();
  head.written += n;
  pipe_bytes_ -= n;
  bytes_delivered_ += n;
  if (head.written == head.bytes.size()) pipe_.pop_front();
}

bool LinkLane::end_due(TimePoint now) const { return !pipe_.empty() && pipe_.front().end && pipe_.front().due <= now; }

void LinkLane::end_delivered() {
  pipe_.pop_front();
  output_ended_ = true;
}

std::optional<LinkLane::TimePoint> LinkLane::next_event(TimePoint now) const {
  std::optional<TimePoint> next;
  if (!queue_.empty() && queue_.front().started) next = queue_.front().leaves;
  if (!pipe_.empty() && pipe_.front().due > now && (!next || pipe_.front().due < *next)) next = pipe_.front().due;
  return next;
}

std::pair<std::size_t, LinkLane::Clock::duration> LinkLane::take_peaks() {
  return {std::exchange(peak_queued_, queued_bytes_), std::exchange(peak_delay_, Clock::duration::zero())};
}

struct LinkEmulator::Impl {
  sockaddr_storage target{};
  socklen_t target_length = 0;
  Fd listener;
  int port = 0;
  Fd wake_read, wake_write;
  std::atomic<bool> stop{false};

  mutable std::mutex mutex;
  mutable std::condition_variable published;
  LinkProfile profile;  // guarded by mutex
  LinkStats stats;      // guarded by mutex

  // The I/O thread's own state.
  std::vector<std::unique_ptr<Connection>> connections;
  Tally up_tally, down_tally;
  std::uint64_t accepted = 0;
  std::uint64_t failures = 0;
  TimePoint accept_paused_until;

  std::thread thread;  // last: started once everything above exists

  void run();
  void accept_all();
  void start_upstream(Connection& connection);
  void finish_connect(Connection& connection);
  void advance(Connection& connection, const LinkProfile& p, TimePoint now);
  void close_dead();
  void publish();
  void wake() const {
    const char byte = 0;
    [[maybe_unused]] const ssize_t ignored = ::write(wake_write.get(), &byte, 1);
  }
};

void LinkEmulator::Impl::run() {
  std::vector<pollfd> fds;
  while (!stop.load()) {
    LinkProfile p;
    {
      std::lock_guard lock(mutex);
      p = profile;
    }
    const LinkLane::Settings up = LinkLane::up(p), down = LinkLane::down(p);

    // Serialize, deliver, and drop the connections that ended.
    const TimePoint now = Clock::now();
    for (auto& connection : connections) advance(*connection, p, now);
    close_dead();

    // Watch the wake-up pipe, the listener, and each socket for what its directions can do now; sleep
    // until the next chunk leaves a queue or falls due.
    fds.clear();
    fds.push_back({wake_read.get(), POLLIN, 0});
    fds.push_back({now >= accept_paused_until ? listener.get() : -1, POLLIN, 0});
    std::optional<TimePoint> next;
    if (now < accept_paused_until) next = accept_paused_until;
    auto earliest = [&next](std::optional<TimePoint> t) {
      if (t && (!next || *t < *next)) next = t;
    };
    for (auto& c : connections) {
      short client_events = 0, upstream_events = 0;
      if (c->up.read_size(up) > 0) client_events |= POLLIN;
      if (!c->down.due(now).empty() || c->down.end_due(now)) client_events |= POLLOUT;
      if (c->connecting) {
        upstream_events = POLLOUT;
      } else {
        if (c->down.read_size(down) > 0) upstream_events |= POLLIN;
        if (!c->up.due(now).empty() || c->up.end_due(now)) upstream_events |= POLLOUT;
      }
      // A socket with nothing to wait for stays out, or its hang-up would wake the loop without end.
      c->poll_index = fds.size();
      fds.push_back({client_events ? c->client.get() : -1, client_events, 0});
      fds.push_back({upstream_events ? c->upstream.get() : -1, upstream_events, 0});
      earliest(c->up.next_event(now));
      earliest(c->down.next_event(now));
    }
    publish();
    timespec timeout{};
    if (next) {
      const auto wait = std::max(Clock::duration::zero(), *next - Clock::now());
      const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
      timeout.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
      timeout.tv_nsec = static_cast<long>(ns % 1'000'000'000);
    }
    if (::ppoll(fds.data(), fds.size(), next ? &timeout : nullptr, nullptr) < 0) {
      if (errno != EINTR) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }

    // Drain the wake-up pipe (stop and set_profile write to it).
    if (fds[0].revents) {
      char sink[64];
      while (::read(wake_read.get(), sink, sizeof sink) > 0) {
      }
    }
    // Read what the senders wrote, and finish connects; writes happen at the next pass.
    for (auto& c : connections) {
      const short client_revents = fds[c->poll_index].revents;
      const short upstream_revents = fds[c->poll_index + 1].revents;
      if (c->connecting && upstream_revents) finish_connect(*c);
      if (client_revents & (POLLIN | POLLHUP | POLLERR)) read_into(c->up, c->client.get(), up);
      if (!c->connecting && (upstream_revents & (POLLIN | POLLHUP | POLLERR)))
        read_into(c->down, c->upstream.get(), down);
    }
    if (fds[1].revents) accept_all();
  }
}

// Accepts every pending client and starts its connection to the target.
void LinkEmulator::Impl::accept_all() {
  for (;;) {
    const int fd = ::accept4(listener.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno == EINTR || errno == ECONNABORTED) continue;
      if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM)
        accept_paused_until = Clock::now() + kAcceptBackoff;
      return;
    }
    auto connection = std::make_unique<Connection>();
    connection->client = Fd(fd);
    tune_socket(fd);
    ++accepted;
    start_upstream(*connection);
    connections.push_back(std::move(connection));
  }
}

// Opens the non-blocking connection to the target; a failure closes the client at the next pass.
void LinkEmulator::Impl::start_upstream(Connection& connection) {
  const int fd = ::socket(target.ss_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    ++failures;
    connection.dead = true;
    return;
  }
  connection.upstream = Fd(fd);
  tune_socket(fd);  // before connect, so the window is negotiated with the small buffer
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&target), target_length) == 0) {
    connection.connecting = false;
  } else if (errno != EINPROGRESS && errno != EINTR) {
    ++failures;
    connection.dead = true;
  }
}

// The target answered the connect: go on relaying, or close the client when it refused.
void LinkEmulator::Impl::finish_connect(Connection& connection) {
  int error = 0;
  socklen_t length = sizeof error;
  if (::getsockopt(connection.upstream.get(), SOL_SOCKET, SO_ERROR, &error, &length) != 0) error = errno;
  if (error == 0) {
    connection.connecting = false;
  } else {
    ++failures;
    connection.dead = true;
  }
}

// Moves serialized chunks on and writes what is due, both ways; marks the connection dead when a
// receiver is gone or both ends of stream are delivered.
void LinkEmulator::Impl::advance(Connection& c, const LinkProfile& p, TimePoint now) {
  if (c.dead) return;
  c.up.advance(LinkLane::up(p), now);
  c.down.advance(LinkLane::down(p), now);
  if (!c.connecting && !deliver(c.up, c.upstream.get(), now)) c.dead = true;
  if (!c.dead && !deliver(c.down, c.client.get(), now)) c.dead = true;
  if (c.up.output_ended() && c.down.output_ended()) c.dead = true;
}

// Closes the connections marked dead, keeping their counts.
void LinkEmulator::Impl::close_dead() {
  std::erase_if(connections, [this](const std::unique_ptr<Connection>& c) {
    if (!c->dead) return false;
    up_tally.read += c->up.bytes_read();
    up_tally.delivered += c->up.bytes_delivered();
    up_tally.add_peaks(c->up);
    down_tally.read += c->down.bytes_read();
    down_tally.delivered += c->down.bytes_delivered();
    down_tally.add_peaks(c->down);
    return true;
  });
}

// Publishes the counters for stats() and wakes wait_until_idle().
void LinkEmulator::Impl::publish() {
  LinkStats s;
  s.connections_accepted = accepted;
  s.connections_open = connections.size();
  s.upstream_failures = failures;
  s.up.bytes_read = up_tally.read;
  s.up.bytes_delivered = up_tally.delivered;
  s.down.bytes_read = down_tally.read;
  s.down.bytes_delivered = down_tally.delivered;
  for (const auto& c : connections) {
    for (auto [lane, out, tally] : {std::tuple{&c->up, &s.up, &up_tally}, std::tuple{&c->down, &s.down, &down_tally}}) {
      out->bytes_read += lane->bytes_read();
      out->bytes_delivered += lane->bytes_delivered();
      out->queued_bytes += lane->queued_bytes();
      out->in_flight_bytes += lane->in_flight_bytes();
      tally->add_peaks(*lane);
    }
  }
  // Peaks since the last publication join the published ones, so that reset_peaks() takes effect.
  auto peaks = [](LinkDirectionStats& out, const LinkDirectionStats& before, Tally& tally) {
    out.max_queued_bytes = std::max(before.max_queued_bytes, tally.peak_queued);
    out.max_queue_delay =
        std::max(before.max_queue_delay, std::chrono::duration_cast<std::chrono::microseconds>(tally.peak_delay));
    tally.peak_queued = 0;
    tally.peak_delay = Clock::duration::zero();
  };
  {
    std::lock_guard lock(mutex);
    peaks(s.up, stats.up, up_tally);
    peaks(s.down, stats.down, down_tally);
    stats = s;
  }
  published.notify_all();
}

LinkProfile link_profile(std::chrono::milliseconds rtt, double cap_mbit) {
  LinkProfile p;
  p.one_way_delay_down = rtt / 2;
  p.one_way_delay_up = rtt - p.one_way_delay_down;
  p.down_mbit = cap_mbit;
  p.up_mbit = cap_mbit;
  return p;
}

LinkEmulator::LinkEmulator(std::string target_host, int target_port, LinkProfile profile)
    : impl_(std::make_unique<Impl>()) {
  validate(profile);
  impl_->profile = profile;

  // The target's address, resolved once.
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(target_port);
  if (const int rc = ::getaddrinfo(target_host.c_str(), service.c_str(), &hints, &found); rc != 0 || !found)
    throw std::runtime_error("LinkEmulator: cannot resolve " + target_host + ": " + ::gai_strerror(rc));
  std::memcpy(&impl_->target, found->ai_addr, found->ai_addrlen);
  impl_->target_length = found->ai_addrlen;
  ::freeaddrinfo(found);

  // The listening socket on 127.0.0.1 at a free port; accepted sockets inherit its small buffers.
  impl_->listener = Fd(::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  const int listen_fd = impl_->listener.get();
  if (listen_fd < 0) throw std::runtime_error(std::string("LinkEmulator: socket: ") + std::strerror(errno));
  tune_socket(listen_fd);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof address;
  if (::bind(listen_fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(listen_fd, 64) != 0 || ::getsockname(listen_fd, reinterpret_cast<sockaddr*>(&address), &length) != 0)
    throw std::runtime_error(std::string("LinkEmulator: listen: ") + std::strerror(errno));
  impl_->port = ntohs(address.sin_port);

  int wake[2];
  if (::pipe2(wake, O_NONBLOCK | O_CLOEXEC) != 0)
    throw std::runtime_error(std::string("LinkEmulator: pipe: ") + std::strerror(errno));
  impl_->wake_read = Fd(wake[0]);
  impl_->wake_write = Fd(wake[1]);

  impl_->thread = std::thread([impl = impl_.get()] { impl->run(); });
}

LinkEmulator::~LinkEmulator() {
  impl_->stop.store(true);
  impl_->wake();
  impl_->thread.join();
}

int LinkEmulator::port() const { return impl_->port; }

void LinkEmulator::set_profile(const LinkProfile& profile) {
  validate(profile);
  {
    std::lock_guard lock(impl_->mutex);
    impl_->profile = profile;
  }
  impl_->wake();
}

LinkProfile LinkEmulator::profile() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->profile;
}

LinkStats LinkEmulator::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

void LinkEmulator::reset_peaks() {
  std::lock_guard lock(impl_->mutex);
  for (LinkDirectionStats* d : {&impl_->stats.up, &impl_->stats.down}) {
    d->max_queued_bytes = 0;
    d->max_queue_delay = std::chrono::microseconds::zero();
  }
}

bool LinkEmulator::wait_until_idle(std::chrono::milliseconds timeout) const {
  std::unique_lock lock(impl_->mutex);
  return impl_->published.wait_for(lock, timeout, [this] { return impl_->stats.connections_open == 0; });
}

}  // namespace rfbsim::test
