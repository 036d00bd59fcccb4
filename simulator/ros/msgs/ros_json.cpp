// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/msgs/ros_json.hpp"

#include <cmath>

namespace rfbsim::ros {

using nlohmann::json;

namespace {

// ---- messages -> JSON, one `js` per type, fields in .msg order ----

// A float as rosbridge writes it: NaN and infinities (a lidar's "no return" in some drivers) become null.
json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json js(const Time& t) { return {{"sec", t.sec}, {"nanosec", t.nanosec}}; }
json js(const Duration& d) { return {{"sec", d.sec}, {"nanosec", d.nanosec}}; }
json js(const Header& h) { return {{"stamp", js(h.stamp)}, {"frame_id", h.frame_id}}; }
json js(const ColorRGBA& c) { return {{"r", num(c.r)}, {"g", num(c.g)}, {"b", num(c.b)}, {"a", num(c.a)}}; }
json js(const Vector3& v) { return {{"x", num(v.x)}, {"y", num(v.y)}, {"z", num(v.z)}}; }
json js(const Point& p) { return {{"x", num(p.x)}, {"y", num(p.y)}, {"z", num(p.z)}}; }
json js(const Quaternion& q) { return {{"x", num(q.x)}, {"y", num(q.y)}, {"z", num(q.z)}, {"w", num(q.w)}}; }
json js(const Pose& p) { return {{"position", js(p.position)}, {"orientation", js(p.orientation)}}; }
json js(const PoseStamped& p) { return {{"header", js(p.header)}, {"pose", js(p.pose)}}; }
json js(const Twist& t) { return {{"linear", js(t.linear)}, {"angular", js(t.angular)}}; }
json js(const TwistStamped& t) { return {{"header", js(t.header)}, {"twist", js(t.twist)}}; }
json js(const Transform& t) { return {{"translation", js(t.translation)}, {"rotation", js(t.rotation)}}; }

json js(const TransformStamped& t) {
  return {{"header", js(t.header)}, {"child_frame_id", t.child_frame_id}, {"transform", js(t.transform)}};
}

template <typename Number>
json numbers(const Number* v, std::size_t n) {
  json out = json::array();
  out.get_ref<json::array_t&>().reserve(n);
  for (std::size_t i = 0; i < n; ++i) out.push_back(num(static_cast<double>(v[i])));
  return out;
}

json js(const PoseWithCovariance& p) {
  return {{"pose", js(p.pose)}, {"covariance", numbers(p.covariance.data(), p.covariance.size())}};
}

json js(const TwistWithCovariance& t) {
  return {{"twist", js(t.twist)}, {"covariance", numbers(t.covariance.data(), t.covariance.size())}};
}

// Element types array_of meets before their definitions below (lookup from a template stops here).
json js(const Person& p);
json js(const Marker& m);

template <typename Element>
json array_of(const std::vector<Element>& elements) {
  json out = json::array();
  out.get_ref<json::array_t&>().reserve(elements.size());
  for (const Element& e : elements) out.push_back(js(e));
  return out;
}

json js(const TFMessage& m) { return {{"transforms", array_of(m.transforms)}}; }
json js(const Clock& c) { return {{"clock", js(c.clock)}}; }

json js(const Odometry& o) {
  return {{"header", js(o.header)},
          {"child_frame_id", o.child_frame_id},
          {"pose", js(o.pose)},
          {"twist", js(o.twist)}};
}

json js(const MapMetaData& m) {
  return {{"map_load_time", js(m.map_load_time)},
          {"resolution", num(m.resolution)},
          {"width", m.width},
          {"height", m.height},
          {"origin", js(m.origin)}};
}

json js(const OccupancyGrid& g) {
  // int8[]: an array of numbers (rosbridge base64-encodes only uint8[] and char[]).
  json data = json::array();
  data.get_ref<json::array_t&>().reserve(g.data.size());
  for (std::int8_t cell : g.data) data.push_back(static_cast<int>(cell));
  return {{"header", js(g.header)}, {"info", js(g.info)}, {"data", std::move(data)}};
}

json js(const Path& p) { return {{"header", js(p.header)}, {"poses", array_of(p.poses)}}; }

json js(const LaserScan& s) {
  return {{"header", js(s.header)},
          {"angle_min", num(s.angle_min)},
          {"angle_max", num(s.angle_max)},
          {"angle_increment", num(s.angle_increment)},
          {"time_increment", num(s.time_increment)},
          {"scan_time", num(s.scan_time)},
          {"range_min", num(s.range_min)},
          {"range_max", num(s.range_max)},
          {"ranges", numbers(s.ranges.data(), s.ranges.size())},
          {"intensities", numbers(s.intensities.data(), s.intensities.size())}};
}

json js(const Person& p) {
  return {{"name", p.name},           {"position", js(p.position)}, {"velocity", js(p.velocity)},
          {"reliability", num(p.reliability)}, {"tagnames", p.tagnames}, {"tags", p.tags}};
}

json js(const People& p) { return {{"header", js(p.header)}, {"people", array_of(p.people)}}; }

json js(const Marker& m) {
  return {{"header", js(m.header)},
          {"ns", m.ns},
          {"id", m.id},
          {"type", m.type},
          {"action", m.action},
          {"pose", js(m.pose)},
          {"scale", js(m.scale)},
          {"color", js(m.color)},
          {"lifetime", js(m.lifetime)},
          {"frame_locked", m.frame_locked},
          {"points", array_of(m.points)},
          {"colors", array_of(m.colors)},
          {"text", m.text},
          {"mesh_resource", m.mesh_resource},
          {"mesh_use_embedded_materials", m.mesh_use_embedded_materials}};
}

json js(const MarkerArray& m) { return {{"markers", array_of(m.markers)}}; }
json js(const String& s) { return {{"data", s.data}}; }

// ---- JSON -> Twist ----

// Reads the object `value` at `path` ("msg.twist.linear") into named numeric fields; false with `error` set
// when it is not an object, has a key the message lacks, or a field that is not a finite number.
bool read_vector(const json& value, const std::string& path, Vector3& out, std::string& error) {
  if (!value.is_object()) {
    error = path + ": expected an object (geometry_msgs/Vector3), got " + value.type_name();
    return false;
  }
  for (const auto& [key, field] : value.items()) {
    double* target = key == "x" ? &out.x : key == "y" ? &out.y : key == "z" ? &out.z : nullptr;
    if (!target) {
      error = path + ": geometry_msgs/Vector3 has no field '" + key + "'";
      return false;
    }
    // Booleans are not numbers here, though JSON libraries in some languages would let them pass.
    if (!field.is_number()) {
      error = path + "." + key + ": expected a number, got " + field.type_name();
      return false;
    }
    *target = field.get<double>();
    if (!std::isfinite(*target)) {
      error = path + "." + key + ": not a finite number";
      return false;
    }
  }
  return true;
}

bool read_twist(const json& value, const std::string& path, Twist& out, std::string& error) {
  if (!value.is_object()) {
    error = path + ": expected an object (geometry_msgs/Twist), got " + value.type_name();
    return false;
  }
  for (const auto& [key, field] : value.items()) {
    if (key == "linear") {
      if (!read_vector(field, path + ".linear", out.linear, error)) return false;
    } else if (key == "angular") {
      if (!read_vector(field, path + ".angular", out.angular, error)) return false;
    } else {
      error = path + ": geometry_msgs/Twist has no field '" + key + "'";
      return false;
    }
  }
  return true;
}

// A TwistStamped's header is checked for shape only: the command takes effect when it arrives.
bool check_header(const json& value, const std::string& path, std::string& error) {
  if (!value.is_object()) {
    error = path + ": expected an object (std_msgs/Header), got " + value.type_name();
    return false;
  }
  for (const auto& [key, field] : value.items()) {
    if (key == "frame_id") {
      if (!field.is_string()) {
        error = path + ".frame_id: expected a string, got " + field.type_name();
        return false;
      }
    } else if (key == "stamp") {
      if (!field.is_object()) {
        error = path + ".stamp: expected an object (builtin_interfaces/Time), got " + field.type_name();
        return false;
      }
      for (const auto& [part, number] : field.items()) {
        if (part != "sec" && part != "nanosec") {
          error = path + ".stamp: builtin_interfaces/Time has no field '" + part + "'";
          return false;
        }
        if (!number.is_number_integer()) {
          error = path + ".stamp." + part + ": expected an integer, got " + number.type_name();
          return false;
        }
      }
    } else {
      error = path + ": std_msgs/Header has no field '" + key + "'";
      return false;
    }
  }
  return true;
}

bool read_twist_stamped(const json& msg, Twist& out, std::string& error) {
  if (!msg.is_object()) {
    error = std::string("msg: expected an object (geometry_msgs/TwistStamped), got ") + msg.type_name();
    return false;
  }
  for (const auto& [key, field] : msg.items()) {
    if (key == "header") {
      if (!check_header(field, "msg.header", error)) return false;
    } else if (key == "twist") {
      if (!read_twist(field, "msg.twist", out, error)) return false;
    } else {
      error = "msg: geometry_msgs/TwistStamped has no field '" + key + "'";
      return false;
    }
  }
  return true;
}

}  // namespace

json to_json(const RosPayload& payload) {
  return std::visit([](const auto& message) { return js(message); }, payload);
}

json to_json(const TwistStamped& message) { return js(message); }

std::optional<Twist> twist_from_json(const json& msg, std::string_view type, std::string& error) {
  bool stamped = false;
  if (type == "geometry_msgs/msg/Twist" || type == "geometry_msgs/Twist") {
    stamped = false;
  } else if (type == "geometry_msgs/msg/TwistStamped" || type == "geometry_msgs/TwistStamped") {
    stamped = true;
  } else if (type.empty()) {
    stamped = msg.is_object() && msg.contains("twist");
  } else {
    error = "type '" + std::string(type) +
            "' is not a velocity command: expected geometry_msgs/msg/Twist or geometry_msgs/msg/TwistStamped";
    return std::nullopt;
  }
  Twist twist;
  const bool ok = stamped ? read_twist_stamped(msg, twist, error) : read_twist(msg, "msg", twist, error);
  if (!ok) return std::nullopt;
  return twist;
}

}  // namespace rfbsim::ros
