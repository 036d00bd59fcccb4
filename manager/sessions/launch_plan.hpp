// SPDX-License-Identifier: GPL-2.0-or-later
// The command line a session is started with, from the config and the participant's link. Pure: the
// arguments are a list (never a shell string), and every value in them was validated before. The
// manager's own flags cannot be overridden by the config's extra arguments.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "admission/start_request.hpp"

namespace rfbsim::manager {

/// Where and with what a session runs.
struct LaunchContext {
  std::uint64_t seed = 0;   ///< the link's seed or a drawn one
  int port = 0;             ///< kRfb: the port picked for the program; kSimRfb: 0 (it picks and reports)
  std::string data_dir;     ///< the session's folder
  /// kSimRfb: the unix socket it serves on (mode 0600: only the manager's user can connect); "" = a loopback
  /// TCP port it picks and reports.
  std::string unix_socket;
  std::int64_t session_id = 0;  ///< the session's index id, which names it under the ROS namespace
  /// kX11: the session's Xauthority file, written fresh by rfbsim_x11_session (beside unix_socket, where only
  /// the manager's user can read it).
  std::string xauthority{};
  /// A video-condition session (kSimRfb): the folder of the session it shows and that session's id; "" = a
  /// live session.
  std::string replay_source{};
  std::int64_t yoked_to = 0;
};

/// What a session is told of ROS (the config's `ros:` section and the link's robot_control).
struct SessionRos {
  /// "<ros.namespace>/<ros_session_name>" when the session dials out to the lab's rosbridge_server: kSimRfb, ros.connect
  /// set and the scenario known to have a robot; "" = no ROS.
  std::string ros_namespace;
  /// Who drives the robot: the link's robot_control, else ros.robot_control where the session has ROS, else
  /// "builtin" for a scenario known to have a robot; "" = no robot known (and the link did not say).
  std::string robot_control;
};

/// The ROS names and control of session `session_id` started for `request`. Pure.
SessionRos session_ros(const ManagerConfig& config, const StartRequest& request, std::int64_t session_id);

/// Why a sim_rfb session cannot be started for `request` as ROS stands ("" when it can): a link's
/// robot_control=external where the session would not dial out to a lab (no ros.connect, or a scenario whose
/// file the manager did not find), so that nothing would drive the robot. A participant sees it (400).
std::string ros_request_problem(const ManagerConfig& config, const StartRequest& request);

/// Arguments after the program name.
///  - kSimRfb: config.session_args first, then the manager's own: --unix-socket PATH (or, without one,
///    --port 0 --bind 127.0.0.1) --rfb-only
///    --ready-fd 3 --scenario S --seed N, one flag per override, with ROS (session_ros) --robot-control C (when
///    the link has none) --rosbridge-connect URL --ros-namespace NS [--rosbridge-token-file F] [--rosbridge-ca F]
///    (never --rosbridge-port: see ros_settings.hpp), --proxy-protocol --data-dir DIR --uid U
///    --codec C (config.codec), --code-success T1 and --code-timeout T2 when the link has them. sim_rfb takes
///    the last of a repeated flag, so the manager's and the link's win over the config's (which
///    session_args_problem refuses for the manager's flags anyway).
///    A video-condition session (context.replay_source) gets instead of --scenario, --seed, the overrides and
///    ROS: --replay DIR --yoked-to ID, and config.session_args less contract::kWorldFlags and their values (a
///    walker's --time-limit must not make the watcher's sim_rfb refuse to start).
///  - kRfb: config.session_args with {port}, {scenario}, {seed}, {uid}, {data_dir}, {t1}, {t2} and one
///    placeholder per override, {avatar_start} {avatar_goal} {robot_start} {robot_goal} {crowd} {robot_control},
///    replaced;
///    a code or override the link does not have becomes "".
///  - kX11: rfbsim_x11_session's --rfb-socket S (context.unix_socket) --xauthority F --geometry WxH --depth D
///    --xvnc PATH --ready-fd 3, then `--` and config.session_command with config.session_args expanded as for
///    kRfb (there is no {port}).
std::vector<std::string> session_arguments(const ManagerConfig& config, const StartRequest& request,
                                           const LaunchContext& context);

/// The sim_rfb flags config.session_args may not name: those the manager sets itself for every session, ROS's
/// (the ros section sets them; sim_rfb's unauthenticated --rosbridge-port is never opened), and --allow-origin
/// (a session is reached only through the relay).
extern const std::vector<std::string> kManagerFlags;

/// Why config.session_args cannot be used with `kind` ("" when they can): for kSimRfb, an argument that
/// is one of kManagerFlags, alone or as --flag=value, e.g. "session_args: --bind is set by sim_manager for
/// every session and cannot be given there". An rfb program's template is its own and is not checked here.
std::string session_args_problem(const std::vector<std::string>& session_args, SessionKind kind);

/// The link's parameters (as validated: uid, scenario, seed, overrides) as a JSON object for the index.
std::string parameters_json(const StartRequest& request, std::uint64_t seed);

}  // namespace rfbsim::manager
