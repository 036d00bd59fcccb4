// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeHub: the thread-safe meeting point between the simulation thread and the network thread(s) of
// the rosbridge v2 server and dial-out client (docs/ros.md). The simulation thread declares what it
// publishes and what it takes, publishes JSON messages and drains what clients sent; the network side opens
// one hub connection per WebSocket, turns client ops into subscriptions and incoming messages
// (ros/bridge/rosbridge_session.hpp), and takes serialized frames out to send.
//
// Ownership: the hub owns every queue; nothing here touches a socket or blocks on the network, and memory is
// bounded everywhere (per-connection outbound bytes, incoming messages). The hub must outlive every server
// and client that uses it. C++17 and C++20 clean; no network type appears here.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "ros/bridge/outbound_queue.hpp"
#include "ros/bridge/ros_names.hpp"
#include "ros/bridge/topic_subscription.hpp"

namespace rfbsim::ros {

/// A message a client published on an accepted topic.
struct IncomingMessage {
  std::string topic;  ///< the simulation's name, without the hub's namespace ("/cmd_vel")
  /// The type as the sender named it (advertise, or a "type" key on the publish), normalized to
  /// pkg/msg/Type; the topic's only accepted type when the sender named none and there is one; else "".
  std::string type;
  nlohmann::json msg;  ///< the message's fields as the client sent them (a JSON object)
  int connection = 0;  ///< the hub connection it came on
};

/// Status message levels, in rosbridge's order of severity ("info" < "warning" < "error"; "none" mutes).
enum class StatusLevel { kInfo = 0, kWarning = 1, kError = 2, kNone = 3 };

/// The wire name of a level ("info", "warning", "error", "none").
std::string_view status_level_name(StatusLevel level);
/// The level a wire name names; nullopt for any other text.
std::optional<StatusLevel> parse_status_level(std::string_view name);

/// How the network side opens a hub connection.
struct HubConnectionOptions {
  /// Frame bytes queued for this connection at most; beyond it the oldest frames are dropped.
  std::size_t max_queued_bytes = std::size_t{8} << 20;
  /// Dial-out: forward every declared topic unthrottled, as if subscribed, and send latched topics' last
  /// message at once. Server connections subscribe topic by topic instead.
  bool mirror_declared = false;
  /// Frames queued first, before anything the hub adds (the dial-out client's advertise/subscribe ops).
  std::vector<std::string> greeting;
  /// Called when the connection's queue goes from empty to non-empty, on whatever thread queued, with the
  /// hub's lock held: it must only hand the work to the network thread (asio post) and never call the hub.
  std::function<void()> wakeup;
  /// Dial-out only: where status messages for this connection go instead of the wire, since a lab's
  /// rosbridge_server has no client-to-server status op (it would answer "unknown operation"). Called with
  /// the text on whatever thread sent the status, without the hub's lock; none: such statuses are dropped.
  std::function<void(const std::string&)> local_status;
};

/// What the hub has done, for tests and metrics.
struct RosbridgeHubStats {
  std::size_t connections = 0;          ///< open now
  std::uint64_t dropped_frames = 0;     ///< outbound frames dropped for slow clients, all connections ever
  std::size_t peak_queued_bytes = 0;    ///< the largest one connection's queue has been, ever
  std::uint64_t throttled_frames = 0;   ///< messages a subscription's throttle skipped
  std::uint64_t dropped_incoming = 0;   ///< client messages dropped because the simulation did not drain
};

/// A declared (simulation-published) topic.
struct DeclaredTopic {
  std::string topic;  ///< "/scan"
  std::string type;   ///< normalized, "sensor_msgs/msg/LaserScan"
  bool latched = false;
};

/// An accepted (client-published) topic.
struct AcceptedTopic {
  std::string topic;               ///< "/cmd_vel"
  std::vector<std::string> types;  ///< normalized, in preference order
};

/// A ROS 2 time (builtin_interfaces/Time): seconds and nanoseconds, as /clock carries it.
struct RosTime {
  std::int32_t sec = 0;       ///< s
  std::uint32_t nanosec = 0;  ///< ns, below 1e9
};

class RosbridgeHub {
 public:
  using Clock = std::chrono::steady_clock;

  /// `topic_namespace`: "" or an absolute name such as "/rfbsim/s1", put in front of every topic on the
  /// wire. Throws std::invalid_argument when it is malformed.
  explicit RosbridgeHub(std::string topic_namespace = "");
  /// As above with a clock for the throttle (tests pass a fake one).
  RosbridgeHub(std::string topic_namespace, std::function<Clock::time_point()> now);
  ~RosbridgeHub();
  RosbridgeHub(const RosbridgeHub&) = delete;
  RosbridgeHub& operator=(const RosbridgeHub&) = delete;

  // --- The simulation thread's side ---

  /// Declares a topic the simulation publishes; call before any server or client starts. `type` in either
  /// spelling. Throws std::invalid_argument for a malformed name or type, or a topic declared or accepted twice.
  void declare(const std::string& topic, const std::string& type, bool latched);
  /// Declares a topic the simulation takes from clients, with its accepted types (either spelling, the
  /// first preferred: the dial-out client subscribes with it). Same errors as declare(). Publishes to
  /// topics neither declared nor accepted get an error status.
  void accept(const std::string& topic, std::vector<std::string> types);
  /// Records the full message definition of `type` (either spelling), as rosapi's topics_and_raw_types
  /// hands it out: the ros2msg text with its dependencies (ros::ros2msg_schema). Any time, any thread; a
  /// second call replaces the text. Throws std::invalid_argument for a malformed type.
  void set_definition(const std::string& type, std::string text);
  /// True when some connection would receive a publish on `topic` now, or the topic is latched (its last
  /// message is kept for later subscribers), or it is a declared /clock (its time is kept for rosapi's
  /// get_time); the simulation skips building JSON otherwise. Cheap.
  [[nodiscard]] bool wanted(const std::string& topic) const;
  /// Sends `msg` on declared `topic` to every subscriber, honouring throttle_rate and queue_length; a
  /// latched topic's message is also kept for each later subscriber. Never blocks on the network. Throws
  /// std::invalid_argument for an undeclared topic (a programmer error).
  void publish(const std::string& topic, nlohmann::json msg);
  /// Messages clients published since the last call, oldest first. Bounded: when the simulation does not
  /// drain, the oldest are dropped (stats().dropped_incoming).
  std::vector<IncomingMessage> take_incoming();
  /// Sends a status message to `connection` (0: every connection) whose status level lets `level` through;
  /// `id` ("" for none) names the operation it is about. Dial-out links log it instead (see local_status).
  void status(int connection, const std::string& level, const std::string& text, const std::string& id = "");

  // --- The network side (server and client threads) ---

  /// Opens a hub connection and returns its id (> 0).
  int open_connection(HubConnectionOptions options);
  /// Forgets a connection, its subscriptions and queue. No wakeup for it runs after this returns.
  void close_connection(int connection);
  /// Pops queued frames for `connection`: at least one when any wait, more while within `max_bytes`.
  std::deque<Frame> take_outgoing(int connection, std::size_t max_bytes);
  /// True while frames wait for `connection`.
  [[nodiscard]] bool has_outgoing(int connection) const;
  /// Frames dropped from `connection`'s queue to keep it within its bound so far (0 for an unknown id).
  [[nodiscard]] std::uint64_t dropped(int connection) const;
  /// Queues throttled messages whose time has come; returns when the next one falls due (nullopt: none wait).
  std::optional<Clock::time_point> flush_due();

  /// Subscribes `connection` to declared `topic` (validated by the caller). Several subscriptions of one
  /// connection to one topic merge as rosbridge does: the lowest throttle and the longest queue win; a
  /// queue_length over kMaxQueueLength counts as kMaxQueueLength. Returns "" when subscribed (or the
  /// connection is gone), else why not: a new id beyond kMaxIdsPerTopic on the topic or beyond
  /// kMaxSubscriptions on the connection is refused and nothing changes.
  std::string subscribe(int connection, const std::string& topic, const SubscribeOptions& options);
  /// Removes `connection`'s subscription `id` on `topic` ("" removes all of them); false when none matched.
  bool unsubscribe(int connection, const std::string& topic, const std::string& id);
  /// Queues an incoming message for take_incoming(); `wire_bytes` is the size of the frame it came in,
  /// counted against kMaxIncomingBytes.
  void push_incoming(IncomingMessage message, std::size_t wire_bytes);
  /// Queues an already serialized frame for `connection` (a reply to one of its ops).
  void send(int connection, std::string frame);
  /// Queues a status message for `connection` if its level lets `level` through; `id` is echoed (null: none).
  /// A dial-out connection gets none on the wire: the text goes to its local_status instead.
  void send_status(int connection, StatusLevel level, const std::string& text, const nlohmann::json& id);
  /// The serialized status message send_status() would queue for `connection`, without queuing it; nullopt
  /// when its level mutes `level`, for a dial-out connection, or an unknown one. For a status that must
  /// overtake the queue (the server's last word before closing a connection).
  [[nodiscard]] std::optional<std::string> status_frame(int connection, StatusLevel level, const std::string& text,
                                                        const nlohmann::json& id) const;
  /// Sets which status messages `connection` receives (set_level op).
  void set_level(int connection, StatusLevel level);

  /// True when `connection` is a dial-out link (opened with mirror_declared), false for a server's client
  /// or an unknown id. Connection ids are always > 0, on both sides.
  [[nodiscard]] bool is_dial_out(int connection) const;
  /// The wire name of a simulation topic: the namespace in front.
  [[nodiscard]] std::string wire_topic(const std::string& topic) const;
  /// The simulation's name for a wire topic (normalized, namespace removed); nullopt when malformed or
  /// outside the namespace.
  [[nodiscard]] std::optional<std::string> local_topic(std::string_view wire) const;
  /// The declared topic named `topic`, if any.
  [[nodiscard]] std::optional<DeclaredTopic> declared(const std::string& topic) const;
  /// The accepted topic named `topic`, if any.
  [[nodiscard]] std::optional<AcceptedTopic> accepted(const std::string& topic) const;
  /// Every declared topic, in declaration order.
  [[nodiscard]] std::vector<DeclaredTopic> declared_topics() const;
  /// Every accepted topic, in order.
  [[nodiscard]] std::vector<AcceptedTopic> accepted_topics() const;
  /// The definition set_definition() recorded for `type` (either spelling); "" when none.
  [[nodiscard]] std::string definition(const std::string& type) const;
  /// The time of the latest well-formed /clock publish ({clock: {sec, nanosec}}); zero before any.
  [[nodiscard]] RosTime last_clock() const;
  /// Counters since construction.
  [[nodiscard]] RosbridgeHubStats stats() const;

  /// Client messages kept at most for take_incoming(), by count and by the bytes of the frames they came
  /// in; far above what a controller sends between two ticks (a Twist is ~150 bytes).
  static constexpr std::size_t kMaxIncoming = 1024;
  static constexpr std::size_t kMaxIncomingBytes = std::size_t{4} << 20;
  /// Status texts are cut to this many bytes ("..." at the end): they may quote what a client sent, and
  /// nlohmann's parse errors write each control byte as 8 characters, so uncut a reply could outgrow its cause.
  static constexpr std::size_t kMaxStatusBytes = 512;
  /// Subscription ids one connection may hold on one topic, and on all topics together: each subscribe with
  /// a new id adds one, and merging them is linear under the lock the simulation thread also takes. Far
  /// above what a tool needs (roslibjs and Foxglove use one per topic and panel).
  static constexpr std::size_t kMaxIdsPerTopic = 32;
  static constexpr std::size_t kMaxSubscriptions = 256;
  /// Messages one subscription holds back behind its throttle_rate at most (a larger queue_length is cut to
  /// this). Each keeps a published message alive outside the connection's byte bound, so that uncut, a
  /// queue_length of 10^9 with an hour's throttle_rate kept everything the simulation published (some
  /// 0.4 MB a second in the warehouse) for as long as the connection lasted. 100 is 3 s of /tf at 30 Hz.
  static constexpr int kMaxQueueLength = 100;
  /// The topic whose time the hub keeps for get_time (rosgraph_msgs/msg/Clock, the simulation's time).
  static constexpr const char* kClockTopic = "/clock";

 private:
  struct Connection;
  struct Topic;

  void enqueue(Connection& connection, Frame frame);
  [[nodiscard]] static std::string status_text(StatusLevel level, const std::string& text, const nlohmann::json& id);
  std::optional<Clock::time_point> flush_due_locked(Clock::time_point now);
  Connection* find(int connection);
  [[nodiscard]] std::optional<DeclaredTopic> find_declared(const std::string& topic) const;
  [[nodiscard]] std::optional<AcceptedTopic> find_accepted(const std::string& topic) const;

  const std::string namespace_;
  const std::function<Clock::time_point()> now_;
  mutable std::mutex mutex_;  // guards everything below
  std::vector<DeclaredTopic> declared_;
  std::vector<AcceptedTopic> accepted_;
  std::map<std::string, Frame> latched_;  // declared latched topic -> its last publish frame
  std::map<std::string, std::string> definitions_;  // normalized type -> full definition text
  RosTime last_clock_;
  std::map<int, std::unique_ptr<Connection>> connections_;
  int next_connection_ = 1;
  std::deque<std::pair<IncomingMessage, std::size_t>> incoming_;  // with its frame's bytes
  std::size_t incoming_bytes_ = 0;
  RosbridgeHubStats stats_;
};

}  // namespace rfbsim::ros
