// SPDX-License-Identifier: GPL-2.0-or-later
// RosLink: the world sampled into ROS messages, to the bag and to rosbridge.
#include "app/ros_link.hpp"

#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <utility>

#include "rfbsim/log.hpp"
#include "ros/bridge/rosbridge_client.hpp"
#include "ros/bridge/rosbridge_hub.hpp"
#include "ros/bridge/rosbridge_server.hpp"
#include "ros/mcap/mcap_writer.hpp"
#include "ros/msgs/ros_cdr.hpp"
#include "ros/msgs/ros_json.hpp"
#include "ros/msgs/ros_schemas.hpp"
#include "ros/msgs/ros_topics.hpp"

namespace rfbsim::sim {

namespace {

constexpr const char* kCmdVel = "/cmd_vel";

}  // namespace

struct RosLink::Impl {
  RosLinkOptions options;
  ros::RosWorldSampler sampler;
  std::unique_ptr<ros::McapWriter> bag;
  std::map<std::string, std::uint16_t> channels;  // topic -> the bag's channel
  std::unique_ptr<ros::RosbridgeHub> hub;
  std::unique_ptr<ros::RosbridgeServer> server;
  std::unique_ptr<ros::RosbridgeClient> client;
  std::vector<ros::RosMessage> due;  // reused every tick
  std::set<int> warned;              // connections told that their commands are ignored
  bool finished = false;

  explicit Impl(RosLinkOptions o) : options(std::move(o)), sampler(ros::RosSamplerOptions{options.tick_hz, 30}) {}

  void open_bag() {
    bag = std::make_unique<ros::McapWriter>(options.bag_file);
    std::map<std::string, std::uint16_t> schemas;  // type -> schema id
    for (const ros::TopicSpec& topic : ros::ros_topics()) {
      auto schema = schemas.find(topic.type);
      if (schema == schemas.end()) {
        schema = schemas.emplace(topic.type, bag->add_schema(topic.type, "ros2msg", ros::ros2msg_schema(topic.type))).first;
      }
      // rosbag2 keeps each topic's QoS in the channel: `ros2 bag play` offers /map transient-local from it.
      std::map<std::string, std::string> metadata = {{"offered_qos_profiles", ros::offered_qos_profiles_yaml(topic.latched)}};
      channels[topic.name] = bag->add_channel(schema->second, options.topic_namespace + topic.name, "cdr", std::move(metadata));
    }
  }

  void open_bridge() {
    hub = std::make_unique<ros::RosbridgeHub>(options.topic_namespace);
    // /cmd_vel goes one way on the bridge: in, from the lab. Echoing the robot's commands back on it would put a
    // second publisher on the lab's /cmd_vel, whose own subscribers (a velocity smoother, a mux) would take our
    // echoes for commands. The bag records what the robot was told; live, /events carries each robot_command.
    for (const ros::TopicSpec& topic : ros::ros_topics()) {
      if (topic.name != kCmdVel) hub->declare(topic.name, topic.type, topic.latched);
    }
    // Both types are taken; the first is the one the dial-out subscribes with.
    const std::string other = options.cmd_vel_type == "geometry_msgs/msg/TwistStamped" ? "geometry_msgs/msg/Twist"
                                                                                        : "geometry_msgs/msg/TwistStamped";
    hub->accept(kCmdVel, {options.cmd_vel_type, other});
    // rosapi's topics_and_raw_types hands each type's definition to Foxglove, Lichtblick and roslibjs, which
    // decode with it.
    for (const ros::TopicSpec& topic : ros::ros_topics()) hub->set_definition(topic.type, ros::ros2msg_schema(topic.type));
    for (const std::string& type : {options.cmd_vel_type, other}) hub->set_definition(type, ros::ros2msg_schema(type));
    if (options.server_port) {
      ros::RosbridgeServerOptions server_options;
      server_options.bind = options.server_bind;
      server_options.port = *options.server_port;
      server = std::make_unique<ros::RosbridgeServer>(*hub, server_options);
    }
    if (!options.connect_url.empty()) {
      ros::RosbridgeClientOptions client_options;
      client_options.url = options.connect_url;
      client_options.token = options.token;
      client_options.ca_file = options.ca_file;
      client = std::make_unique<ros::RosbridgeClient>(*hub, client_options);
    }
  }

  void hand_out(const std::vector<ros::RosMessage>& messages) {
    for (const ros::RosMessage& message : messages) {
      if (bag) {
        const std::vector<std::uint8_t> cdr = ros::to_cdr(message.payload);
        bag->write(channels.at(message.topic->name), message.time_ns, message.time_ns, cdr.data(), cdr.size());
      }
      // JSON only for someone listening: most ticks nobody subscribes to most topics.
      if (hub && message.topic->name != kCmdVel && hub->wanted(message.topic->name)) hub->publish(message.topic->name, ros::to_json(message.payload));
    }
  }
};

RosLink::RosLink(RosLinkOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  if (!impl_->options.bag_file.empty()) impl_->open_bag();
  if (impl_->options.server_port || !impl_->options.connect_url.empty()) impl_->open_bridge();
}

RosLink::~RosLink() { finish(); }

void RosLink::sample(const World& world, const RobotStack* robot) {
  if (impl_->finished) return;
  impl_->due.clear();
  impl_->sampler.sample(world, robot, impl_->due);
  impl_->hand_out(impl_->due);
}

void RosLink::event(std::uint64_t tick, const std::string& json_line) {
  if (impl_->finished) return;
  impl_->due.clear();
  // A viewer's hashed address stays in events.jsonl on this server: /events may go to a lab's ROS graph, and the
  // hash would let it link one participant's sessions.
  if (json_line.find("\"address\"") != std::string::npos) {
    nlohmann::ordered_json event = nlohmann::ordered_json::parse(json_line, nullptr, false);
    if (event.is_object()) {
      event.erase("address");
      impl_->sampler.add_event(ros::tick_time_ns(tick, impl_->options.tick_hz), event.dump(), impl_->due);
      impl_->hand_out(impl_->due);
      return;
    }
  }
  impl_->sampler.add_event(ros::tick_time_ns(tick, impl_->options.tick_hz), json_line, impl_->due);
  impl_->hand_out(impl_->due);
}

std::vector<RobotCommand> RosLink::take_commands() {
  std::vector<RobotCommand> commands;
  if (!impl_->hub) return commands;
  for (ros::IncomingMessage& incoming : impl_->hub->take_incoming()) {
    if (incoming.topic != kCmdVel) continue;  // the hub refuses topics we do not accept
    std::string error;
    const auto twist = ros::twist_from_json(incoming.msg, incoming.type, error);
    if (!twist) {
      impl_->hub->status(incoming.connection, "error", "/cmd_vel: " + error);
      continue;
    }
    const bool dial_out = impl_->hub->is_dial_out(incoming.connection);
    commands.push_back({twist->linear.x, twist->angular.z, dial_out ? "rosbridge-client" : "rosbridge", incoming.connection});
  }
  return commands;
}

void RosLink::warn_ignored(const RobotCommand& command, const std::string& why) {
  if (!impl_->hub || !impl_->warned.insert(command.connection).second) return;
  impl_->hub->status(command.connection, "warning", why);
  rfbsim::log::limited(rfbsim::log::Level::kWarn, "cmd-vel-ignored", "ros", "/cmd_vel ignored: %s", why.c_str());
}

void RosLink::flush_if_due() {
  if (impl_->bag) impl_->bag->flush_if_due();
}

void RosLink::finish() {
  if (impl_->finished) return;
  impl_->finished = true;
  // The bag first: every message is in it already, and the bridge's goodbyes (up to a second each, more when a
  // lab is unreachable) must not spend the time sim_manager gives a session between SIGTERM and SIGKILL.
  if (impl_->bag) {
    impl_->bag->finish();
    if (const auto failure = impl_->bag->failure()) {
      rfbsim::log::info("ros", "session.mcap is incomplete: %s", failure->c_str());
    }
  }
  impl_->client.reset();
  impl_->server.reset();
}

std::optional<int> RosLink::server_port() const {
  if (!impl_->server) return std::nullopt;
  return impl_->server->port();
}

bool RosLink::writes_bag() const { return impl_->bag != nullptr; }

std::optional<std::string> RosLink::bag_failure() const {
  if (!impl_->bag) return std::nullopt;
  return impl_->bag->failure();
}

std::string RosLink::bridge_description() const {
  std::string text;
  if (impl_->server) text = "server " + url_host(impl_->options.server_bind) + ":" + std::to_string(impl_->server->port());
  if (impl_->client) text += (text.empty() ? "" : " + ") + std::string("client ") + impl_->options.connect_url;
  return text;
}

std::string url_host(const std::string& address) {
  return address.find(':') != std::string::npos ? "[" + address + "]" : address;
}

}  // namespace rfbsim::sim
