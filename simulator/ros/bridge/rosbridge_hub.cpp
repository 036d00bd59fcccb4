// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeHub: topics, connections with their subscriptions, bounded queues, all behind one mutex. Each
// subscription's throttle and queue semantics (rosbridge_suite's ROSBRIDGE_PROTOCOL.md, "subscribe") are
// TopicSubscription's (topic_subscription.hpp); the hub decides who gets a message and queues what is due.
#include "ros/bridge/rosbridge_hub.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <utility>

namespace rfbsim::ros {

struct RosbridgeHub::Connection {
  explicit Connection(HubConnectionOptions options)
      : queue(options.max_queued_bytes),
        mirror(options.mirror_declared),
        wakeup(std::move(options.wakeup)),
        local_status(std::move(options.local_status)) {}
  OutboundQueue queue;
  bool mirror;
  std::function<void()> wakeup;
  std::function<void(const std::string&)> local_status;
  // Default "warning", where rosbridge_suite mutes warnings: our warnings say when an option is not
  // honoured (compression) or a command is ignored, which a lab wants to see unasked.
  StatusLevel level = StatusLevel::kWarning;
  std::map<std::string, TopicSubscription> subscriptions;  // by topic
  std::size_t subscription_ids = 0;                        // by_id entries over all topics
};

std::string_view status_level_name(StatusLevel level) {
  switch (level) {
    case StatusLevel::kInfo: return "info";
    case StatusLevel::kWarning: return "warning";
    case StatusLevel::kError: return "error";
    case StatusLevel::kNone: return "none";
  }
  return "none";
}

std::optional<StatusLevel> parse_status_level(std::string_view name) {
  for (const StatusLevel level : {StatusLevel::kInfo, StatusLevel::kWarning, StatusLevel::kError, StatusLevel::kNone}) {
    if (status_level_name(level) == name) return level;
  }
  return std::nullopt;
}

namespace {

std::string checked_namespace(const std::string& ns) {
  std::optional<std::string> normalized = normalize_namespace(ns);
  if (!normalized) throw std::invalid_argument("RosbridgeHub: malformed topic namespace '" + ns + "'");
  return *normalized;
}

std::string checked_topic(const std::string& topic) {
  std::optional<std::string> normalized = normalize_topic(topic);
  if (!normalized) throw std::invalid_argument("RosbridgeHub: malformed topic name '" + topic + "'");
  return *normalized;
}

std::string checked_type(const std::string& topic, const std::string& type) {
  std::string normalized = normalize_ros_type(type);
  if (normalized.empty()) {
    throw std::invalid_argument("RosbridgeHub: malformed message type '" + type + "' for " + topic);
  }
  return normalized;
}

// Client strings may hold invalid UTF-8; replace it rather than throw on the way out.
std::string dump(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// `text` within kMaxStatusBytes: cut before a UTF-8 character that would not fit whole, then "...".
std::string bounded_status_text(const std::string& text, std::size_t max_bytes) {
  if (text.size() <= max_bytes) return text;
  std::size_t end = max_bytes - 3;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;  // a continuation byte
  return text.substr(0, end) + "...";
}

// The time a /clock message carries (rosgraph_msgs/msg/Clock: {clock: {sec, nanosec}}, as ros_json writes
// it); nullopt when a field is missing or out of builtin_interfaces/Time's range.
std::optional<RosTime> clock_time(const nlohmann::json& msg) {
  if (!msg.is_object()) return std::nullopt;
  const auto clock = msg.find("clock");
  if (clock == msg.end() || !clock->is_object()) return std::nullopt;
  const auto sec = clock->find("sec");
  const auto nanosec = clock->find("nanosec");
  if (sec == clock->end() || nanosec == clock->end() || !sec->is_number_integer() ||
      !nanosec->is_number_integer()) {
    return std::nullopt;
  }
  const auto whole = sec->get<std::int64_t>();
  const auto fraction = nanosec->get<std::int64_t>();
  if (whole < std::numeric_limits<std::int32_t>::min() || whole > std::numeric_limits<std::int32_t>::max() ||
      fraction < 0 || fraction >= 1'000'000'000) {
    return std::nullopt;
  }
  return RosTime{static_cast<std::int32_t>(whole), static_cast<std::uint32_t>(fraction)};
}

}  // namespace

RosbridgeHub::RosbridgeHub(std::string topic_namespace)
    : RosbridgeHub(std::move(topic_namespace), [] { return Clock::now(); }) {}

RosbridgeHub::RosbridgeHub(std::string topic_namespace, std::function<Clock::time_point()> now)
    : namespace_(checked_namespace(topic_namespace)), now_(std::move(now)) {}

RosbridgeHub::~RosbridgeHub() = default;

// --- The simulation thread's side ---

void RosbridgeHub::declare(const std::string& topic, const std::string& type, bool latched) {
  DeclaredTopic entry{checked_topic(topic), checked_type(topic, type), latched};
  const std::lock_guard lock(mutex_);
  if (find_declared(entry.topic) || find_accepted(entry.topic)) {
    throw std::invalid_argument("RosbridgeHub: topic " + entry.topic + " declared twice");
  }
  declared_.push_back(std::move(entry));
}

void RosbridgeHub::accept(const std::string& topic, std::vector<std::string> types) {
  AcceptedTopic entry{checked_topic(topic), {}};
  if (types.empty()) throw std::invalid_argument("RosbridgeHub: no type accepted on " + entry.topic);
  for (const std::string& type : types) entry.types.push_back(checked_type(entry.topic, type));
  const std::lock_guard lock(mutex_);
  if (find_declared(entry.topic) || find_accepted(entry.topic)) {
    throw std::invalid_argument("RosbridgeHub: topic " + entry.topic + " declared twice");
  }
  accepted_.push_back(std::move(entry));
}

void RosbridgeHub::set_definition(const std::string& type, std::string text) {
  const std::string normalized = checked_type("set_definition", type);
  const std::lock_guard lock(mutex_);
  definitions_[normalized] = std::move(text);
}

bool RosbridgeHub::wanted(const std::string& topic) const {
  const std::lock_guard lock(mutex_);
  for (const DeclaredTopic& entry : declared_) {
    if (entry.topic == topic && (entry.latched || topic == kClockTopic)) return true;
  }
  for (const auto& [id, connection] : connections_) {
    if (connection->mirror || connection->subscriptions.count(topic) != 0) return true;
  }
  return false;
}

void RosbridgeHub::publish(const std::string& topic, nlohmann::json msg) {
  // Serialize once for every receiver, only when someone (or the latch) will take it, and outside the lock:
  // a /map is megabytes, and the network threads take the lock for every frame they send. A subscriber that
  // arrives in between misses this one message, as it would a moment earlier.
  const std::optional<DeclaredTopic> entry = declared(topic);
  if (!entry) throw std::invalid_argument("RosbridgeHub: publish on undeclared topic " + topic);
  const std::optional<RosTime> time = topic == kClockTopic ? clock_time(msg) : std::nullopt;
  Frame frame;
  if (entry->latched || wanted(topic)) {
    frame = std::make_shared<const std::string>("{\"op\":\"publish\",\"topic\":" + dump(namespace_ + topic) +
                                                ",\"msg\":" + dump(msg) + "}");
  }

  const std::lock_guard lock(mutex_);
  const Clock::time_point now = now_();
  // The simulation's time, kept for rosapi's get_time whether or not anyone subscribes to /clock.
  if (time) last_clock_ = *time;
  if (frame) {
    if (entry->latched) latched_[topic] = frame;
    for (auto& [id, connection] : connections_) {
      if (connection->mirror) {
        enqueue(*connection, frame);
        continue;
      }
      // Out now, or held back (or dropped) by the subscription's throttle.
      const auto subscription = connection->subscriptions.find(topic);
      if (subscription != connection->subscriptions.end() &&
          subscription->second.offer(frame, now, stats_.throttled_frames)) {
        enqueue(*connection, frame);
      }
    }
  }
  // Each tick's publishes also release what other topics' throttles held back.
  flush_due_locked(now);
}

std::vector<IncomingMessage> RosbridgeHub::take_incoming() {
  const std::lock_guard lock(mutex_);
  std::vector<IncomingMessage> taken;
  taken.reserve(incoming_.size());
  for (auto& [message, bytes] : incoming_) taken.push_back(std::move(message));
  incoming_.clear();
  incoming_bytes_ = 0;
  return taken;
}

void RosbridgeHub::status(int connection, const std::string& level, const std::string& text, const std::string& id) {
  const std::optional<StatusLevel> parsed = parse_status_level(level);
  if (!parsed || *parsed == StatusLevel::kNone) {
    throw std::invalid_argument("RosbridgeHub::status: level must be info, warning or error, not '" + level + "'");
  }
  const nlohmann::json id_json = id.empty() ? nlohmann::json() : nlohmann::json(id);
  if (connection != 0) {
    send_status(connection, *parsed, text, id_json);
    return;
  }
  std::vector<int> ids;
  {
    const std::lock_guard lock(mutex_);
    for (const auto& [key, value] : connections_) ids.push_back(key);
  }
  for (const int key : ids) send_status(key, *parsed, text, id_json);
}

// --- The network side ---

int RosbridgeHub::open_connection(HubConnectionOptions options) {
  const std::lock_guard lock(mutex_);
  const int id = next_connection_++;
  std::vector<std::string> greeting = std::move(options.greeting);
  auto connection = std::make_unique<Connection>(std::move(options));
  for (std::string& frame : greeting) enqueue(*connection, std::make_shared<const std::string>(std::move(frame)));
  // A dial-out link hears every latched topic's last message at once, as a new subscriber would.
  if (connection->mirror) {
    for (const DeclaredTopic& entry : declared_) {
      const auto frame = latched_.find(entry.topic);
      if (frame != latched_.end()) enqueue(*connection, frame->second);
    }
  }
  connections_.emplace(id, std::move(connection));
  stats_.connections = connections_.size();
  return id;
}

void RosbridgeHub::close_connection(int connection) {
  const std::lock_guard lock(mutex_);
  const auto found = connections_.find(connection);
  if (found == connections_.end()) return;
  // Keep its counters: a slow client's drops matter most once it has gone.
  stats_.dropped_frames += found->second->queue.dropped();
  stats_.peak_queued_bytes = std::max(stats_.peak_queued_bytes, found->second->queue.peak_bytes());
  connections_.erase(found);
  stats_.connections = connections_.size();
}

std::deque<Frame> RosbridgeHub::take_outgoing(int connection, std::size_t max_bytes) {
  const std::lock_guard lock(mutex_);
  Connection* found = find(connection);
  if (found == nullptr) return {};
  return found->queue.pop(max_bytes);
}

bool RosbridgeHub::has_outgoing(int connection) const {
  const std::lock_guard lock(mutex_);
  const auto found = connections_.find(connection);
  return found != connections_.end() && !found->second->queue.empty();
}

std::uint64_t RosbridgeHub::dropped(int connection) const {
  const std::lock_guard lock(mutex_);
  const auto found = connections_.find(connection);
  return found == connections_.end() ? 0 : found->second->queue.dropped();
}

std::optional<RosbridgeHub::Clock::time_point> RosbridgeHub::flush_due() {
  const std::lock_guard lock(mutex_);
  return flush_due_locked(now_());
}

std::string RosbridgeHub::subscribe(int connection, const std::string& topic, const SubscribeOptions& options) {
  const std::lock_guard lock(mutex_);
  Connection* found = find(connection);
  if (found == nullptr) return "";
  // A new id adds an entry; the same id again only replaces its options, so it is never refused.
  const auto existing = found->subscriptions.find(topic);
  const bool new_id = existing == found->subscriptions.end() || existing->second.by_id.count(options.id) == 0;
  if (new_id && existing != found->subscriptions.end() && existing->second.by_id.size() >= kMaxIdsPerTopic) {
    return "already " + std::to_string(kMaxIdsPerTopic) + " subscriptions to this topic on this connection";
  }
  if (new_id && found->subscription_ids >= kMaxSubscriptions) {
    return "already " + std::to_string(kMaxSubscriptions) + " subscriptions on this connection";
  }
  TopicSubscription& subscription = found->subscriptions[topic];
  SubscribeOptions& kept = subscription.by_id[options.id];
  kept = options;
  kept.queue_length = std::min(options.queue_length, kMaxQueueLength);
  if (new_id) ++found->subscription_ids;
  subscription.merge();
  // Latched: the new subscriber hears the last message at once, whatever the throttle.
  const auto frame = latched_.find(topic);
  if (frame != latched_.end()) enqueue(*found, frame->second);
  return "";
}

bool RosbridgeHub::unsubscribe(int connection, const std::string& topic, const std::string& id) {
  const std::lock_guard lock(mutex_);
  Connection* found = find(connection);
  if (found == nullptr) return false;
  const auto subscription = found->subscriptions.find(topic);
  if (subscription == found->subscriptions.end()) return false;
  if (id.empty()) {
    found->subscription_ids -= subscription->second.by_id.size();
    found->subscriptions.erase(subscription);
    return true;
  }
  if (subscription->second.by_id.erase(id) == 0) return false;
  --found->subscription_ids;
  if (subscription->second.by_id.empty()) {
    found->subscriptions.erase(subscription);
  } else {
    subscription->second.merge();
  }
  return true;
}

void RosbridgeHub::push_incoming(IncomingMessage message, std::size_t wire_bytes) {
  const std::lock_guard lock(mutex_);
  incoming_.emplace_back(std::move(message), wire_bytes);
  incoming_bytes_ += wire_bytes;
  // Oldest first; the newest stays even when it alone is over the byte bound.
  while (incoming_.size() > kMaxIncoming || (incoming_bytes_ > kMaxIncomingBytes && incoming_.size() > 1)) {
    incoming_bytes_ -= incoming_.front().second;
    incoming_.pop_front();
    ++stats_.dropped_incoming;
  }
}

void RosbridgeHub::send(int connection, std::string frame) {
  const std::lock_guard lock(mutex_);
  Connection* found = find(connection);
  if (found != nullptr) enqueue(*found, std::make_shared<const std::string>(std::move(frame)));
}

void RosbridgeHub::send_status(int connection, StatusLevel level, const std::string& text, const nlohmann::json& id) {
  std::function<void(const std::string&)> local_status;
  {
    const std::lock_guard lock(mutex_);
    Connection* found = find(connection);
    if (found == nullptr || found->level == StatusLevel::kNone || level < found->level) return;
    if (!found->mirror) {
      enqueue(*found, std::make_shared<const std::string>(status_text(level, text, id)));
      return;
    }
    local_status = found->local_status;
  }
  // A dial-out link: a lab's rosbridge_server takes no status op, so the text stays here (outside the lock:
  // the sink logs).
  if (local_status) local_status(std::string(status_level_name(level)) + ": " + text);
}

std::optional<std::string> RosbridgeHub::status_frame(int connection, StatusLevel level, const std::string& text,
                                                      const nlohmann::json& id) const {
  const std::lock_guard lock(mutex_);
  const auto found = connections_.find(connection);
  if (found == connections_.end() || found->second->mirror || found->second->level == StatusLevel::kNone ||
      level < found->second->level) {
    return std::nullopt;
  }
  return status_text(level, text, id);
}

void RosbridgeHub::set_level(int connection, StatusLevel level) {
  const std::lock_guard lock(mutex_);
  Connection* found = find(connection);
  if (found != nullptr) found->level = level;
}

bool RosbridgeHub::is_dial_out(int connection) const {
  const std::lock_guard lock(mutex_);
  const auto found = connections_.find(connection);
  return found != connections_.end() && found->second->mirror;
}

std::string RosbridgeHub::wire_topic(const std::string& topic) const { return namespace_ + topic; }

std::optional<std::string> RosbridgeHub::local_topic(std::string_view wire) const {
  std::optional<std::string> topic = normalize_topic(wire);
  if (!topic || namespace_.empty()) return topic;
  // "/rfbsim/s1/cmd_vel" -> "/cmd_vel"; "/rfbsim/s10/x" is outside "/rfbsim/s1".
  if (topic->size() <= namespace_.size() + 1 || topic->compare(0, namespace_.size(), namespace_) != 0 ||
      (*topic)[namespace_.size()] != '/') {
    return std::nullopt;
  }
  return topic->substr(namespace_.size());
}

std::optional<DeclaredTopic> RosbridgeHub::declared(const std::string& topic) const {
  const std::lock_guard lock(mutex_);
  return find_declared(topic);
}

std::optional<AcceptedTopic> RosbridgeHub::accepted(const std::string& topic) const {
  const std::lock_guard lock(mutex_);
  return find_accepted(topic);
}

std::optional<DeclaredTopic> RosbridgeHub::find_declared(const std::string& topic) const {
  for (const DeclaredTopic& entry : declared_) {
    if (entry.topic == topic) return entry;
  }
  return std::nullopt;
}

std::optional<AcceptedTopic> RosbridgeHub::find_accepted(const std::string& topic) const {
  for (const AcceptedTopic& entry : accepted_) {
    if (entry.topic == topic) return entry;
  }
  return std::nullopt;
}

std::vector<DeclaredTopic> RosbridgeHub::declared_topics() const {
  const std::lock_guard lock(mutex_);
  return declared_;
}

std::vector<AcceptedTopic> RosbridgeHub::accepted_topics() const {
  const std::lock_guard lock(mutex_);
  return accepted_;
}

std::string RosbridgeHub::definition(const std::string& type) const {
  const std::string normalized = normalize_ros_type(type);
  const std::lock_guard lock(mutex_);
  const auto found = definitions_.find(normalized);
  return found == definitions_.end() ? std::string() : found->second;
}

RosTime RosbridgeHub::last_clock() const {
  const std::lock_guard lock(mutex_);
  return last_clock_;
}

RosbridgeHubStats RosbridgeHub::stats() const {
  const std::lock_guard lock(mutex_);
  RosbridgeHubStats stats = stats_;
  for (const auto& [id, connection] : connections_) {
    stats.peak_queued_bytes = std::max(stats.peak_queued_bytes, connection->queue.peak_bytes());
    stats.dropped_frames += connection->queue.dropped();
  }
  return stats;
}

// --- Private, called with mutex_ held ---

std::string RosbridgeHub::status_text(StatusLevel level, const std::string& text, const nlohmann::json& id) {
  nlohmann::json status = {{"op", "status"},
                            {"level", status_level_name(level)},
                            {"msg", bounded_status_text(text, kMaxStatusBytes)}};
  if (!id.is_null()) status["id"] = id;
  return dump(status);
}

void RosbridgeHub::enqueue(Connection& connection, Frame frame) {
  if (connection.queue.push(std::move(frame)) && connection.wakeup) connection.wakeup();
}

std::optional<RosbridgeHub::Clock::time_point> RosbridgeHub::flush_due_locked(Clock::time_point now) {
  std::optional<Clock::time_point> next;
  for (auto& [id, connection] : connections_) {
    for (auto& [topic, subscription] : connection->subscriptions) {
      // At most one held-back message per subscription and call: the throttle starts again with it.
      if (Frame frame = subscription.take_due(now)) enqueue(*connection, std::move(frame));
      const std::optional<Clock::time_point> due = subscription.next_due();
      if (due && (!next || *due < *next)) next = due;
    }
  }
  return next;
}

RosbridgeHub::Connection* RosbridgeHub::find(int connection) {
  const auto found = connections_.find(connection);
  return found == connections_.end() ? nullptr : found->second.get();
}

}  // namespace rfbsim::ros
