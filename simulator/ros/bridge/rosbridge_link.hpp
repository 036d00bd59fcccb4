// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeLink: the dial-out side of rosbridge v2 as pure protocol. Toward a lab's rosbridge_server rfbsim
// is the client: on each connection it advertises every declared topic and subscribes to every accepted one
// (greeting()), then the hub forwards the declared topics' publishes; the server's publishes on accepted
// topics become incoming messages (on_text()). RosbridgeClient moves the bytes.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "ros/bridge/rosbridge_hub.hpp"

namespace rfbsim::ros {

class RosbridgeLink {
 public:
  /// `log` receives one line per noteworthy event (the server's warnings and errors, frames we could not
  /// use); the caller decides how often to print it.
  RosbridgeLink(RosbridgeHub& hub, std::function<void(const std::string&)> log)
      : hub_(hub), log_(std::move(log)) {}

  /// The ops that open every connection: an advertise per declared topic (with "latch" for latched ones),
  /// then a subscribe per accepted topic with its first type. Types in the short pkg/Type spelling, which
  /// rosbridge_server resolves on ROS 1 and ROS 2 alike; topics namespaced.
  [[nodiscard]] std::vector<std::string> greeting() const;
  /// Handles one text frame from the server, arriving on hub connection `connection`.
  void on_text(int connection, std::string_view text);

 private:
  RosbridgeHub& hub_;
  std::function<void(const std::string&)> log_;
};

}  // namespace rfbsim::ros
