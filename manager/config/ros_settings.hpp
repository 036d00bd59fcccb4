// SPDX-License-Identifier: GPL-2.0-or-later
// The config's `ros:` section: each session of a scenario with a robot dials out to a lab's rosbridge_server
// (sim_rfb's --rosbridge-connect), under a namespace of its own, so that the lab's ROS stack can drive the
// robot without any port opened on the study server (issue 20). The checks of its values and the session's
// ROS names are here; which sessions get them and their flags are in launch_plan.
//
// sim_manager never starts a session with --rosbridge-port: sim_rfb's rosbridge server has no authentication,
// so any local user (or a participant's code on a shared host) that reached it could drive the robot or read
// the session. Dialling out, with the lab's token and TLS, has the lab's server do the authenticating.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace rfbsim::manager {

/// The `ros:` section (flags --ros-connect, --ros-token-file, --ros-ca-file, --ros-namespace,
/// --ros-robot-control, --ros-cmd-vel-type). Without `connect` there is no ROS: nothing is added to any session.
struct RosSettings {
  std::string connect;     ///< the lab's rosbridge_server, ws:// or wss://; "" = no ROS
  std::string token_file;  ///< absolute path of a file holding a Bearer token for the dial-out; "" = none
  std::string ca_file;     ///< absolute path of extra PEM CA certificates for wss; "" = the system's only
  std::string ros_namespace = "/rfbsim";  ///< a ROS name; each session's topics go under <namespace>/<session>
  /// Who drives the robot where a link does not say: "builtin" (the simulator's own planner), "external"
  /// (/cmd_vel from the lab's stack), or "" = what the scenario's `robot.control` says (builtin when it says nothing).
  std::string robot_control;
  /// The type of the lab's /cmd_vel: "twist" (geometry_msgs/msg/Twist) or "twist_stamped" (Jazzy-era stacks).
  std::string cmd_vel_type = "twist";
};

/// A ROS graph name as sim_rfb's --ros-namespace takes it: '/', then one or more segments of [A-Za-z0-9_] that
/// start with a letter, joined by single '/', with no trailing '/'; at most contract::kMaxRosRootName (200)
/// characters, so that each session's name under it fits sim_rfb's limit. E.g. "/rfbsim/s_12".
bool is_ros_name(std::string_view name);

/// Why `url` cannot be the lab's rosbridge_server ("" when it can): ws:// or wss://, then a host (and optional
/// port and path) of visible ASCII with no user info (credentials belong in token_file: a URL is shown in
/// `ps`, logs and the admin page), at most 2048 characters.
std::string rosbridge_url_problem(std::string_view url);

/// Why the file at `path` cannot be the dial-out's token ("" when it can). Reads it: one line of 1..4096
/// visible ASCII characters (a trailing newline is allowed), so that it cannot break the Authorization header.
/// The token itself never appears in the message.
std::string token_file_problem(const std::string& path);

/// Why the file at `path` cannot be the CA certificates for wss ("" when it can). Reads it: it must hold at
/// least one PEM certificate.
std::string ca_file_problem(const std::string& path);

/// The name of session `session_id` under the namespace: "s_<id>", and with several hosts "s_<id>_<host>"
/// with the host id's '-' as '_' (cluster host ids are [a-z0-9-], so the name stays unique across hosts).
/// Never the participant's uid: it is theirs, and may hold characters a ROS name cannot.
std::string ros_session_name(std::int64_t session_id, const std::string& cluster_host_id);

}  // namespace rfbsim::manager
