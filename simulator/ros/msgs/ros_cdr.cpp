// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/msgs/ros_cdr.hpp"

#include "ros/mcap/cdr_writer.hpp"

namespace rfbsim::ros {

namespace {

// One `put` per type, each writing its fields in .msg order (ros_schemas.cpp holds the same definitions).

void put(CdrWriter& w, const Time& t) {
  w.i32(t.sec);
  w.u32(t.nanosec);
}

void put(CdrWriter& w, const Duration& d) {
  w.i32(d.sec);
  w.u32(d.nanosec);
}

void put(CdrWriter& w, const Header& h) {
  put(w, h.stamp);
  w.string(h.frame_id);
}

void put(CdrWriter& w, const ColorRGBA& c) {
  w.f32(c.r);
  w.f32(c.g);
  w.f32(c.b);
  w.f32(c.a);
}

void put(CdrWriter& w, const Vector3& v) {
  w.f64(v.x);
  w.f64(v.y);
  w.f64(v.z);
}

void put(CdrWriter& w, const Point& p) {
  w.f64(p.x);
  w.f64(p.y);
  w.f64(p.z);
}

void put(CdrWriter& w, const Quaternion& q) {
  w.f64(q.x);
  w.f64(q.y);
  w.f64(q.z);
  w.f64(q.w);
}

void put(CdrWriter& w, const Pose& p) {
  put(w, p.position);
  put(w, p.orientation);
}

void put(CdrWriter& w, const PoseStamped& p) {
  put(w, p.header);
  put(w, p.pose);
}

void put(CdrWriter& w, const Twist& t) {
  put(w, t.linear);
  put(w, t.angular);
}

void put(CdrWriter& w, const TwistStamped& t) {
  put(w, t.header);
  put(w, t.twist);
}

void put(CdrWriter& w, const Transform& t) {
  put(w, t.translation);
  put(w, t.rotation);
}

void put(CdrWriter& w, const TransformStamped& t) {
  put(w, t.header);
  w.string(t.child_frame_id);
  put(w, t.transform);
}

void put(CdrWriter& w, const PoseWithCovariance& p) {
  put(w, p.pose);
  w.f64_array(p.covariance.data(), p.covariance.size());  // float64[36]: fixed, no length
}

void put(CdrWriter& w, const TwistWithCovariance& t) {
  put(w, t.twist);
  w.f64_array(t.covariance.data(), t.covariance.size());
}

void put(CdrWriter& w, const TFMessage& m) {
  w.sequence_length(m.transforms.size());
  for (const TransformStamped& t : m.transforms) put(w, t);
}

void put(CdrWriter& w, const Clock& c) { put(w, c.clock); }

void put(CdrWriter& w, const Odometry& o) {
  put(w, o.header);
  w.string(o.child_frame_id);
  put(w, o.pose);
  put(w, o.twist);
}

void put(CdrWriter& w, const MapMetaData& m) {
  put(w, m.map_load_time);
  w.f32(m.resolution);
  w.u32(m.width);
  w.u32(m.height);
  put(w, m.origin);
}

void put(CdrWriter& w, const OccupancyGrid& g) {
  put(w, g.header);
  put(w, g.info);
  w.sequence_length(g.data.size());
  w.bytes(g.data.data(), g.data.size());
}

void put(CdrWriter& w, const Path& p) {
  put(w, p.header);
  w.sequence_length(p.poses.size());
  for (const PoseStamped& pose : p.poses) put(w, pose);
}

void put(CdrWriter& w, const LaserScan& s) {
  put(w, s.header);
  w.f32(s.angle_min);
  w.f32(s.angle_max);
  w.f32(s.angle_increment);
  w.f32(s.time_increment);
  w.f32(s.scan_time);
  w.f32(s.range_min);
  w.f32(s.range_max);
  w.sequence_length(s.ranges.size());
  w.f32_array(s.ranges.data(), s.ranges.size());
  w.sequence_length(s.intensities.size());
  w.f32_array(s.intensities.data(), s.intensities.size());
}

void put(CdrWriter& w, const std::vector<std::string>& strings) {
  w.sequence_length(strings.size());
  for (const std::string& s : strings) w.string(s);
}

void put(CdrWriter& w, const Person& p) {
  w.string(p.name);
  put(w, p.position);
  put(w, p.velocity);
  w.f64(p.reliability);
  put(w, p.tagnames);
  put(w, p.tags);
}

void put(CdrWriter& w, const People& p) {
  put(w, p.header);
  w.sequence_length(p.people.size());
  for (const Person& person : p.people) put(w, person);
}

void put(CdrWriter& w, const Marker& m) {
  put(w, m.header);
  w.string(m.ns);
  w.i32(m.id);
  w.i32(m.type);
  w.i32(m.action);
  put(w, m.pose);
  put(w, m.scale);
  put(w, m.color);
  put(w, m.lifetime);
  w.boolean(m.frame_locked);
  w.sequence_length(m.points.size());
  for (const Point& p : m.points) put(w, p);
  w.sequence_length(m.colors.size());
  for (const ColorRGBA& c : m.colors) put(w, c);
  w.string(m.text);
  w.string(m.mesh_resource);
  w.boolean(m.mesh_use_embedded_materials);
}

void put(CdrWriter& w, const MarkerArray& m) {
  w.sequence_length(m.markers.size());
  for (const Marker& marker : m.markers) put(w, marker);
}

void put(CdrWriter& w, const String& s) { w.string(s.data); }

template <typename Message>
std::vector<std::uint8_t> encode(const Message& message) {
  CdrWriter w;
  put(w, message);
  return w.take();
}

}  // namespace

std::vector<std::uint8_t> to_cdr(const RosPayload& payload) {
  return std::visit([](const auto& message) { return encode(message); }, payload);
}

std::vector<std::uint8_t> to_cdr(const Clock& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const TFMessage& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const Odometry& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const LaserScan& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const OccupancyGrid& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const Twist& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const TwistStamped& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const People& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const Path& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const MarkerArray& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const String& message) { return encode(message); }
std::vector<std::uint8_t> to_cdr(const PoseStamped& message) { return encode(message); }

}  // namespace rfbsim::ros
