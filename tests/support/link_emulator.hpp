// SPDX-License-Identifier: GPL-2.0-or-later
// LinkEmulator: a loopback TCP relay that makes the path between a client and a server behave like a slow,
// distant network link (a propagation delay and a rate-capped bottleneck with a bounded queue, each way),
// for tests and network benchmarks.
//
// The model, per direction (up = client -> server, down = server -> client):
//   1. The emulator reads what the sender wrote, in chunks (at most 16 KiB; with a rate cap, about 2 ms
//      of that rate, at least 1448 bytes, so a large write spreads over time as packets would).
//   2. Each chunk enters the bottleneck queue. The queue drains at the rate cap: a chunk of N bytes leaves
//      N * 8 / rate seconds after the previous one left, or after it arrived if the link was idle.
//      Without a cap a chunk leaves as soon as it arrives.
//   3. A chunk that left the queue reaches the receiver one-way delay later; bytes are written to the
//      receiver in order, never lost, duplicated or reordered, each at its due time (to about a
//      millisecond: steady_clock deadlines, ppoll with nanosecond timeouts).
//   4. Backpressure: while a capped direction's queue holds bottleneck_queue_bytes, or while
//      window_bytes have left the queue but not yet been taken by the receiver, the emulator stops
//      reading from the sender. The sender's socket buffer then fills and its writes block (or fail
//      with EAGAIN), as behind a real bottleneck or a closed TCP window. The emulator's own socket
//      buffers are kept small (SO_RCVBUF and SO_SNDBUF 64 KiB, which Linux doubles) so they hide
//      little of that; every socket has TCP_NODELAY and an Ethernet MSS (TCP_MAXSEG 1460), so the
//      endpoints' kernels segment and size their buffers as on a real path, not for loopback's 64 KiB.
//   5. End of stream travels like data: after the sender shuts down or closes its side, the receiver
//      gets every byte queued before it and then an end of stream (shutdown(SHUT_WR)) at the due time.
//      Half-closed connections keep working the other way. A read error (a reset) counts as an end of
//      stream; a failed write (the receiver is gone) ends the whole connection at once, both sockets.
//
// What it does not emulate: loss, reordering, jitter, duplication; header overhead (the cap counts payload
// bytes: a real 10 Mbit/s link carries about 9.6 Mbit/s of TCP payload); the TCP handshake (a client's
// connect() completes at once; the emulator then connects to the target with no delay); the time
// acknowledgements take to come back (without a cap, one direction carries at most window_bytes per one-way
// delay, where a real TCP connection carries its window per round trip); slow start and the other
// congestion control of the real endpoints (their kernels see a loopback path with a tiny RTT and no
// loss). Both sockets of a relayed connection are plain loopback TCP, so a sender's own send buffer adds
// to the standing queue it builds: Linux grows it on its own unless the sender sets SO_SNDBUF (a greedy
// sender through 5 Mbit/s gets about 2 MB accepted before its writes block: seconds of queue).
//
// Threads: one I/O thread per emulator runs every connection (a ppoll loop); every public member may be
// called from any thread.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace rfbsim::test {

/// How the emulated link behaves; may be changed while connections are open (LinkEmulator::set_profile).
struct LinkProfile {
  /// Propagation delay server -> client (down), added after the bottleneck; >= 0.
  std::chrono::milliseconds one_way_delay_down{0};
  /// Propagation delay client -> server (up); >= 0.
  std::chrono::milliseconds one_way_delay_up{0};
  /// Bottleneck rate server -> client in Mbit/s (10^6 bits per second); 0 = no cap.
  double down_mbit = 0;
  /// Bottleneck rate client -> server in Mbit/s; 0 = no cap.
  double up_mbit = 0;
  /// Bytes the bottleneck queue holds per direction before the emulator stops reading from the sender
  /// (capped directions only); > 0. 256 KiB at 5 Mbit/s is about 420 ms of queue.
  std::size_t bottleneck_queue_bytes = 256 * 1024;
  /// Bytes per direction that may be past the bottleneck but not yet taken by the receiver (in
  /// propagation, or waiting because the receiver does not read) before the emulator stops reading
  /// from the sender, like a TCP receive window; > 0. Bounds the emulator's memory; the default (4 MiB)
  /// lets an uncapped direction carry up to 4 MiB per one-way delay (about 335 Mbit/s at 100 ms).
  std::size_t window_bytes = 4 * 1024 * 1024;
};

/// A symmetric link: `rtt` split evenly between the directions (an odd millisecond goes up) and the same
/// rate cap (`cap_mbit`, Mbit/s, 0 = none) both ways; the queue and window take their defaults.
LinkProfile link_profile(std::chrono::milliseconds rtt, double cap_mbit = 0);

/// Counters for one direction, summed over every connection the emulator has relayed.
struct LinkDirectionStats {
  /// Bytes read from the senders.
  std::uint64_t bytes_read = 0;
  /// Bytes written to the receivers.
  std::uint64_t bytes_delivered = 0;
  /// Bytes in the bottleneck queues now.
  std::size_t queued_bytes = 0;
  /// Bytes past the bottleneck but not yet written to the receivers now.
  std::size_t in_flight_bytes = 0;
  /// The most bytes one connection's bottleneck queue has held (since start or reset_peaks()).
  std::size_t max_queued_bytes = 0;
  /// The longest time one chunk took from being read to leaving the bottleneck queue, its own
  /// serialization included (since start or reset_peaks()); microseconds.
  std::chrono::microseconds max_queue_delay{0};
};

/// A snapshot of an emulator's counters, current as of the I/O thread's last pass (it publishes before
/// every wait). Copy it out; it does not update.
struct LinkStats {
  LinkDirectionStats up;    ///< client -> server
  LinkDirectionStats down;  ///< server -> client
  /// Client connections accepted so far.
  std::uint64_t connections_accepted = 0;
  /// Relayed connections still open (accepted and not yet ended on both sides).
  std::uint64_t connections_open = 0;
  /// Accepted connections closed because the target could not be reached (refused, unreachable).
  std::uint64_t upstream_failures = 0;
};

/// One direction of one relayed connection as a pure model, on the caller's clock and without sockets:
/// the bottleneck queue, then the pipe (propagation, then waiting for the receiver to take the bytes).
/// LinkEmulator runs two per connection; it is public so that its timing can be tested exactly.
class LinkLane {
 public:
  using Clock = std::chrono::steady_clock;
  using TimePoint = Clock::time_point;

  /// One direction's share of a LinkProfile.
  struct Settings {
    Clock::duration delay{};       ///< one-way propagation delay
    double mbit = 0;               ///< bottleneck rate, Mbit/s; 0 = no cap
    std::size_t queue_bytes = 0;   ///< LinkProfile::bottleneck_queue_bytes
    std::size_t window_bytes = 0;  ///< LinkProfile::window_bytes
  };
  /// The client -> server settings of `profile`.
  static Settings up(const LinkProfile& profile);
  /// The server -> client settings of `profile`.
  static Settings down(const LinkProfile& profile);

  /// How many bytes to read from the sender now: what the queue limit (capped) and the window leave
  /// room for, and at most one chunk (16 KiB; with a cap about 2 ms of the rate, at least 1448 bytes).
  /// 0 once the end of stream is in.
  [[nodiscard]] std::size_t read_size(const Settings& settings) const;
  /// `bytes` (not empty), read from the sender at `arrived`, join the bottleneck queue; `arrived` is
  /// not before the previous push.
  void push(std::vector<char> bytes, TimePoint arrived);
  /// The sender's end of stream, seen at `arrived`, joins the queue; nothing may be pushed after it.
  void push_end(TimePoint arrived);
  /// Passes through the bottleneck every chunk whose serialization is over by `now`: a chunk starts when
  /// it arrived or when the one before it left, whichever is later, takes size * 8 / rate (the rate in
  /// force when it starts), and falls due `settings.delay` after it leaves.
  void advance(const Settings& settings, TimePoint now);
  /// The undelivered bytes of the first chunk in the pipe, when it is due at `now`; empty otherwise.
  /// Valid until the next call that changes the lane.
  [[nodiscard]] std::span<const char> due(TimePoint now) const;
  /// `n` (<= due().size()) bytes of due() were written to the receiver.
  void consume(std::size_t n);
  /// Whether the end of stream is due at `now`, with every byte before it delivered.
  [[nodiscard]] bool end_due(TimePoint now) const;
  /// The end of stream was delivered (the receiver's socket was shut down for writing).
  void end_delivered();
  /// The next time after `now` at which a chunk leaves the queue or falls due; none when nothing waits
  /// on time (empty, or only a chunk already due that the receiver has not taken).
  [[nodiscard]] std::optional<TimePoint> next_event(TimePoint now) const;

  [[nodiscard]] std::size_t queued_bytes() const { return queued_bytes_; }          ///< in the bottleneck queue
  [[nodiscard]] std::size_t in_flight_bytes() const { return pipe_bytes_; }         ///< past it, undelivered
  [[nodiscard]] bool input_ended() const { return input_ended_; }                   ///< push_end() was called
  [[nodiscard]] bool output_ended() const { return output_ended_; }                 ///< end_delivered() was called
  [[nodiscard]] std::uint64_t bytes_read() const { return bytes_read_; }            ///< pushed, in all
  [[nodiscard]] std::uint64_t bytes_delivered() const { return bytes_delivered_; }  ///< consumed, in all
  /// The peaks of queued_bytes() and of a chunk's time from arrival to leaving the queue since the last
  /// call (or since the start); restarts them from now (the queue peak from queued_bytes()).
  std::pair<std::size_t, Clock::duration> take_peaks();

 private:
  struct Chunk {
    std::vector<char> bytes;  // empty for the end of stream
    bool end = false;
    TimePoint arrived;
    bool started = false;  // `leaves` is set: the chunk is at the head of the queue
    TimePoint leaves;      // its last bit is through the bottleneck
    TimePoint due;         // it reaches the receiver
    std::size_t written = 0;
  };
  std::deque<Chunk> queue_;
  std::deque<Chunk> pipe_;
  std::size_t queued_bytes_ = 0;
  std::size_t pipe_bytes_ = 0;
  TimePoint link_free_;  // when the last chunk to leave the queue left it
  bool input_ended_ = false;
  bool output_ended_ = false;
  std::uint64_t bytes_read_ = 0;
  std::uint64_t bytes_delivered_ = 0;
  std::size_t peak_queued_ = 0;
  Clock::duration peak_delay_{};
};

/// The relay itself: a listening port on 127.0.0.1, one I/O thread, two LinkLanes per connection.
class LinkEmulator {
 public:
  /// Resolves `target_host` (a name or a numeric address), listens on 127.0.0.1 at a free port and starts
  /// the I/O thread. Each accepted connection gets its own connection to target_host:target_port; a
  /// target that refuses gets the client's connection closed. Throws std::invalid_argument for a bad
  /// profile, std::runtime_error when the host does not resolve or the listening socket fails.
  LinkEmulator(std::string target_host, int target_port, LinkProfile profile = {});
  /// Stops the I/O thread, joins it and closes every socket at once; queued data is dropped.
  ~LinkEmulator();
  LinkEmulator(const LinkEmulator&) = delete;
  LinkEmulator& operator=(const LinkEmulator&) = delete;

  /// The port on 127.0.0.1 where clients connect.
  [[nodiscard]] int port() const;

  /// Replaces the profile for every connection, open or future. Chunks already past the bottleneck keep
  /// their delivery time; a new rate applies from the next chunk to start serializing; delivery stays in
  /// order (a shorter delay never lets bytes overtake earlier ones). Throws std::invalid_argument for a
  /// negative delay or rate, a non-finite rate, or a zero queue or window.
  void set_profile(const LinkProfile& profile);
  /// The profile in force.
  [[nodiscard]] LinkProfile profile() const;

  /// The counters now (see LinkStats).
  [[nodiscard]] LinkStats stats() const;
  /// Sets the peaks (max_queued_bytes, max_queue_delay) back to zero, e.g. between benchmark phases.
  void reset_peaks();
  /// Waits until no relayed connection is open (a client whose connect() just returned may not be
  /// accepted yet, and does not count); false after `timeout`.
  bool wait_until_idle(std::chrono::milliseconds timeout) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfbsim::test
