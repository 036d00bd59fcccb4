// SPDX-License-Identifier: GPL-2.0-or-later
// ROS name rules (ROS 2 "Topic and Service name mapping" design doc and ROS 1 wiki "Names"): a name token is
// letters, digits and underscores and does not start with a digit; a message type is package/msg/Type, which
// ROS 1 and roslibjs write package/Type.
#include "ros/bridge/ros_names.hpp"

#include <vector>

namespace rfbsim::ros {

namespace {

bool is_token(std::string_view token) {
  if (token.empty()) return false;
  if (token.front() >= '0' && token.front() <= '9') return false;
  for (const char c : token) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) return false;
  }
  return true;
}

std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

}  // namespace

std::string normalize_ros_type(std::string_view type) {
  const std::vector<std::string_view> parts = split(type, '/');
  for (const std::string_view part : parts) {
    if (!is_token(part)) return "";
  }
  if (parts.size() == 2) return std::string(parts[0]) + "/msg/" + std::string(parts[1]);
  if (parts.size() == 3 && parts[1] == "msg") return std::string(type);
  return "";
}

std::string short_ros_type(std::string_view type) {
  const std::string normalized = normalize_ros_type(type);
  if (normalized.empty()) return "";
  const std::size_t first = normalized.find('/');
  return normalized.substr(0, first) + normalized.substr(normalized.rfind('/'));
}

std::optional<std::string> normalize_topic(std::string_view topic) {
  if (topic.empty()) return std::nullopt;
  const std::string_view relative = topic.front() == '/' ? topic.substr(1) : topic;
  for (const std::string_view part : split(relative, '/')) {
    if (!is_token(part)) return std::nullopt;
  }
  return "/" + std::string(relative);
}

std::optional<std::string> normalize_service(std::string_view service) { return normalize_topic(service); }

std::optional<std::string> normalize_namespace(std::string_view ns) {
  if (ns.empty()) return std::string();
  if (ns.front() != '/') return std::nullopt;
  if (ns.size() > 1 && ns.back() == '/') ns.remove_suffix(1);
  return normalize_topic(ns);
}

}  // namespace rfbsim::ros
