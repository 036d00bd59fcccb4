// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb's command line: parsed and validated without side effects, so that it can be unit-tested.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::sim {

/// Everything sim_rfb can be told on its command line.
struct SimOptions {
  int port = 5901;                  ///< 0 = any free port
  std::string bind = "127.0.0.1";   ///< listen address; loopback unless told otherwise
  int width = 1280;                 ///< frame width, pixels
  int height = 720;                 ///< frame height, pixels
  int fps = 30;                     ///< frames rendered per second while a client is connected
  int tick_hz = 60;                 ///< fixed simulation steps per second
  std::optional<std::uint64_t> seed;  ///< master seed for every random stream; unset = the scenario's
  std::string scenario;             ///< scenario name or path; empty = the built-in test room
  /// Scenario overrides: a spawn point's name or "x,y,yaw" (checked when the scenario is loaded).
  std::optional<std::string> avatar_start, avatar_goal, robot_start, robot_goal;
  std::optional<int> crowd;         ///< number of pedestrians instead of the scenario's
  int jpeg_quality = 80;            ///< 1..100
  /// Picture encoding for clients: "auto" (Tight JPEG, H.264 once a client's link needs it), "jpeg" or "h264"
  /// (rfbsim::Codec; kept as text here so that the options need no librfbsim).
  std::string codec = "auto";
  int max_clients = 4;
  std::string web_root;             ///< empty = the built or installed page
  std::string egl_platform = "auto";
  std::string log_level = "info";   ///< error, warn, info or debug (rfbsim/log.hpp)
  bool debug_overlay = false;       ///< draw the robot's path, trajectory, goal and social cost (for developers)
  /// Serve RFB only (raw and over WebSocket): no page, no /status.json, no web root looked for.
  bool rfb_only = false;
  /// Each connection begins with a PROXY protocol line naming the real client (sim_manager's relay).
  bool proxy_protocol = false;
  /// Pages allowed to open the stream besides the server's own and loopback ones (--allow-origin, repeatable):
  /// "scheme://host[:port]" or "*" (rfbsim::ServerOptions::allowed_origins).
  std::vector<std::string> allowed_origins;
  /// Listen on this unix socket (mode 0600) instead of TCP; empty = TCP on bind:port.
  std::string unix_socket;
  /// Once listening, write "ready <port>\n" ("ready unix <path>\n" on a unix socket) to this file
  /// descriptor (3 or above), then about once a second
  /// while someone watches a "stream ..." line (app/stream_status.hpp), and one line per outcome
  /// ("outcome completed\n"); closed when the program ends.
  std::optional<int> ready_fd;
  std::string data_dir;             ///< record session data here (docs/data.md); empty = nothing recorded
  /// Play this recorded session folder to viewers instead of a live one (docs/replay.md); empty = live.
  std::string replay;
  /// With --replay: the recorded session's id in sim_manager's index, written as the watcher's yoked_to.
  std::optional<std::int64_t> yoked_to;
  std::string uid;                  ///< participant id for session.json
  std::string code_success;         ///< completion code shown on success (SEAN-EP's t1); empty = none
  std::string code_timeout;         ///< completion code shown on timeout (t2); empty = none
  std::optional<int> time_limit;    ///< s, the task's time limit instead of the scenario's
  std::optional<int> end_grace;     ///< s the outcome stays on screen before the end, instead of the scenario's
  int trajectory_hz = 10;           ///< trajectory rows per second; divides tick_hz
  bool mcap = true;                 ///< with data_dir, also write session.mcap (--no-mcap: not)
  /// Who drives the robot: "builtin" or "external" (a link parameter like the poses; unset = the scenario's).
  std::optional<std::string> robot_control;
  /// The participant's view: "third_person" or "first_person" (a link parameter too; unset = the scenario's).
  std::optional<std::string> camera;
  /// ROS (docs/ros.md): a rosbridge v2 server on this port (0 = any free port), unauthenticated, so loopback
  /// by default; and/or a rosbridge client dialling out to `rosbridge_connect` (ws:// or wss://).
  std::optional<int> rosbridge_port;
  std::string rosbridge_bind = "127.0.0.1";
  std::string rosbridge_connect;
  std::string rosbridge_token_file;  ///< its first line is sent as a Bearer token when dialling out
  std::string rosbridge_ca;          ///< extra CA certificates for wss://
  std::string ros_namespace;         ///< prefix of every topic on the wire ("" or e.g. /rfbsim/s1)
  /// The type the dial-out subscribes to /cmd_vel with (a lab's rosbridge_server needs one): Twist, or
  /// TwistStamped as Jazzy-era stacks publish it. Our own server takes either whatever this says.
  std::string cmd_vel_type = "geometry_msgs/msg/Twist";
  bool help = false;
};

/// The outcome of parsing: options, or a message naming the bad argument.
struct ParseOutcome {
  SimOptions options;
  std::string error;  ///< empty on success
};

/// Parses argv (without the program name). Never throws; never exits.
ParseOutcome parse_sim_options(const std::vector<std::string>& args);

/// The --help text.
std::string sim_usage();

}  // namespace rfbsim::sim
