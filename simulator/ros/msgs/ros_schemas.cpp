// SPDX-License-Identifier: GPL-2.0-or-later
#include "ros/msgs/ros_schemas.hpp"

#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace rfbsim::ros {

namespace {

// The .msg files of ROS 2 Humble (common_interfaces 4.2, rcl_interfaces' builtin_interfaces and
// rosgraph_msgs, the people repository's ros2 branch), comments and blank lines left out, fields and constants
// as written there. Nested types are spelled as the files spell them (unqualified within their own package).
const std::map<std::string, std::string, std::less<>>& msg_texts() {
  static const std::map<std::string, std::string, std::less<>> texts = {
      {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
      {"builtin_interfaces/Duration", "int32 sec\nuint32 nanosec\n"},
      {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
      {"std_msgs/String", "string data\n"},
      {"std_msgs/ColorRGBA", "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n"},
      {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
      {"geometry_msgs/Pose", "Point position\nQuaternion orientation\n"},
      {"geometry_msgs/PoseStamped", "std_msgs/Header header\nPose pose\n"},
      {"geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"},
      {"geometry_msgs/TwistStamped", "std_msgs/Header header\nTwist twist\n"},
      {"geometry_msgs/Transform", "Vector3 translation\nQuaternion rotation\n"},
      {"geometry_msgs/TransformStamped", "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"},
      {"geometry_msgs/PoseWithCovariance", "Pose pose\nfloat64[36] covariance\n"},
      {"geometry_msgs/TwistWithCovariance", "Twist twist\nfloat64[36] covariance\n"},
      {"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"},
      {"rosgraph_msgs/Clock", "builtin_interfaces/Time clock\n"},
      {"nav_msgs/Odometry",
       "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
       "geometry_msgs/TwistWithCovariance twist\n"},
      {"nav_msgs/MapMetaData",
       "builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\nuint32 height\n"
       "geometry_msgs/Pose origin\n"},
      {"nav_msgs/OccupancyGrid", "std_msgs/Header header\nMapMetaData info\nint8[] data\n"},
      {"nav_msgs/Path", "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n"},
      {"sensor_msgs/LaserScan",
       "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n"
       "float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\nfloat32[] ranges\n"
       "float32[] intensities\n"},
      {"people_msgs/Person",
       "string name\ngeometry_msgs/Point position\ngeometry_msgs/Point velocity\nfloat64 reliability\n"
       "string[] tagnames\nstring[] tags\n"},
      {"people_msgs/People", "std_msgs/Header header\npeople_msgs/Person[] people\n"},
      // Humble's Marker: no ARROW_STRIP constant and none of texture_resource, texture, uv_coordinates and
      // mesh_file, which Iron and Jazzy added.
      {"visualization_msgs/Marker",
       "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\nint32 LINE_LIST=5\n"
       "int32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\nint32 TEXT_VIEW_FACING=9\n"
       "int32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n"
       "int32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n"
       "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\n"
       "geometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\n"
       "bool frame_locked\ngeometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring text\n"
       "string mesh_resource\nbool mesh_use_embedded_materials\n"},
      {"visualization_msgs/MarkerArray", "Marker[] markers\n"},
  };
  return texts;
}

const std::set<std::string, std::less<>>& primitive_types() {
  static const std::set<std::string, std::less<>> primitives = {
      "bool",  "byte",   "char",  "float32", "float64", "int8",   "uint8",
      "int16", "uint16", "int32", "uint32",  "int64",   "uint64", "string", "wstring"};
  return primitives;
}

// The nested types a .msg text uses, as "pkg/Type" (unqualified names belong to `package`), in name order: the
// order rosbag2 appends them in.
std::set<std::string> dependencies(const std::string& text, const std::string& package) {
  std::set<std::string> deps;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::string type = line.substr(0, line.find(' '));
    type = type.substr(0, type.find('['));  // "Point[]" and "float64[36]" name their element type
    if (type.empty() || primitive_types().contains(type)) continue;
    deps.insert(type.find('/') == std::string::npos ? package + "/" + type : type);
  }
  return deps;
}

void append_definition(const std::string& name, std::string& out, std::set<std::string>& seen) {
  const auto found = msg_texts().find(name);
  if (found == msg_texts().end()) throw std::logic_error("ros2msg: no definition of nested type " + name);
  // The rule and "MSG: pkg/Type", as rosbag2_storage_mcap writes it. rosbag2's docs/message_definition_encoding.md
  // shows "MSG: pkg/msg/Type", but Foxglove's and Lichtblick's parser (@foxglove/rosmsg 5) cannot resolve that
  // form: ros_msgs_npm_decode fails with it.
  if (!out.empty()) out += "\n" + std::string(80, '=') + "\nMSG: " + name + "\n";
  out += found->second;
  for (const std::string& dep : dependencies(found->second, name.substr(0, name.find('/')))) {
    if (seen.insert(dep).second) append_definition(dep, out, seen);
  }
}

}  // namespace

std::string ros2msg_schema(std::string_view type) {
  // "pkg/msg/Type" -> "pkg/Type", the key the definitions are filed under.
  std::string name(type);
  if (const auto at = name.find("/msg/"); at != std::string::npos) name.erase(at, 4);
  if (name.find('/') == std::string::npos || !msg_texts().contains(name)) {
    throw std::invalid_argument("ros2msg: unknown message type '" + std::string(type) + "'");
  }
  std::string out;
  std::set<std::string> seen{name};
  append_definition(name, out, seen);
  return out;
}

}  // namespace rfbsim::ros
