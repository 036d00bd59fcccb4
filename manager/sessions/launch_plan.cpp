// SPDX-License-Identifier: GPL-2.0-or-later
// Session command lines.
#include "sessions/launch_plan.hpp"

#include <algorithm>

#include "contract/replay_flags.hpp"
#include "sessions/session_process.hpp"
#include "http/web_policy.hpp"

namespace rfbsim::manager {

namespace {

// Replaces every placeholder of `values` in one pass over `text`: a value put in is never searched again
// (a scenario file "/srv/{uid}.yaml" stays as it is).
std::string expand(const std::string& text, const std::vector<std::pair<std::string, std::string>>& values) {
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const auto match = std::find_if(values.begin(), values.end(),
                                    [&](const auto& value) { return text.compare(at, value.first.size(), value.first) == 0; });
    if (match == values.end()) {
      out.push_back(text[at++]);
    } else {
      out += match->second;
      at += match->first.size();
    }
  }
  return out;
}

// config.session_args with the link's and the session's values put in (session_arguments, kRfb and kX11).
std::vector<std::string> expand_template(const ManagerConfig& config, const StartRequest& request,
                                         const LaunchContext& context, const std::string& scenario) {
  std::vector<std::pair<std::string, std::string>> values = {{"{scenario}", scenario},
                                                              {"{seed}", std::to_string(context.seed)},
                                                              {"{uid}", request.uid},
                                                              {"{t1}", request.code_success},
                                                              {"{t2}", request.code_timeout},
                                                              {"{data_dir}", context.data_dir}};
  // An x11 program draws on its display: it has no port (validate_config refuses {port} there).
  if (config.session_kind == SessionKind::kRfb) values.emplace_back("{port}", std::to_string(context.port));
  // The link's overrides too, each as {name} (empty when the link has none): validated like sim_rfb's,
  // they are the study's conditions, and a program whose template leaves them out never sees them.
  for (const OverrideParam& param : kOverrideParams) {
    const auto given = std::find_if(request.overrides.begin(), request.overrides.end(),
                                    [&param](const auto& override_) { return override_.first == param.name; });
    values.emplace_back("{" + std::string(param.name) + "}",
                        given == request.overrides.end() ? std::string() : given->second);
  }
  std::vector<std::string> args;
  for (const std::string& arg : config.session_args) args.push_back(expand(arg, values));
  return args;
}

// config.session_args less the flags that make a world (contract::kWorldFlags), each with its value: what a
// watcher's sim_rfb --replay is given of them.
std::vector<std::string> without_world_flags(const std::vector<std::string>& session_args) {
  std::vector<std::string> kept;
  for (std::size_t i = 0; i < session_args.size(); ++i) {
    const std::string& arg = session_args[i];
    const std::string flag = arg.substr(0, arg.find('='));
    if (std::find(contract::kWorldFlags.begin(), contract::kWorldFlags.end(), flag) == contract::kWorldFlags.end()) {
      kept.push_back(arg);
    } else if (flag == arg) {
      ++i;  // --flag VALUE: the value goes too
    }
  }
  return kept;
}

// The end of every sim_rfb session's command line: where its data goes and for whom, how it streams, its codes.
std::vector<std::string> with_session_record(const ManagerConfig& config, const StartRequest& request,
                                             const LaunchContext& context, std::vector<std::string> args) {
  // Session data goes to the session's folder; the codes are shown in the picture when the task ends. The
  // relay names each browser's address in a PROXY line, which sim_rfb records hashed.
  args.insert(args.end(), {"--proxy-protocol", "--data-dir", context.data_dir, "--uid", request.uid});
  // The picture encoding, always named, so that the session's command line says what it ran with.
  args.insert(args.end(), {"--codec", config.codec});
  if (!request.code_success.empty()) args.insert(args.end(), {"--code-success", request.code_success});
  // A watcher cannot run out of time: their code is t1, shown and sent when the recording has been shown.
  if (!request.code_timeout.empty() && context.replay_source.empty()) {
    args.insert(args.end(), {"--code-timeout", request.code_timeout});
  }
  return args;
}

}  // namespace

// Where sim_rfb listens and how it reports (--bind, --port, --unix-socket, --ready-fd, --rfb-only,
// --web-root, --proxy-protocol) decide who can reach a participant's session and whether the relay's
// PROXY line is trusted; where it records and as whom (--data-dir, --uid) and with what (--scenario,
// --seed, --codec) are what the index says of the session. None may come from anywhere but the manager.
// --allow-origin is not the manager's, but would only open a session to pages other than through the
// relay, which checks the Origin itself.
// ROS's flags are the ros section's and the link's; --rosbridge-port and --rosbridge-bind would open sim_rfb's
// rosbridge server, which has no authentication: any local user or participant who reached it could drive the
// robot or read the session, so the manager never opens it.
const std::vector<std::string> kManagerFlags = {
    "--bind", "--port", "--unix-socket", "--ready-fd", "--rfb-only", "--web-root", "--proxy-protocol", "--data-dir",
    "--uid", "--scenario", "--seed", "--codec", "--allow-origin",
    // ROS (issue 20)
    "--robot-control", "--rosbridge-connect", "--rosbridge-token-file", "--rosbridge-ca", "--ros-namespace",
    "--rosbridge-port", "--rosbridge-bind", "--cmd-vel-type"};

std::string session_args_problem(const std::vector<std::string>& session_args, SessionKind kind) {
  if (kind != SessionKind::kSimRfb) return "";
  for (const std::string& arg : session_args) {
    const std::string flag = arg.substr(0, arg.find('='));
    if (std::find(kManagerFlags.begin(), kManagerFlags.end(), flag) == kManagerFlags.end()) continue;
    if (flag == "--rosbridge-port" || flag == "--rosbridge-bind") {
      return "session_args: " + flag + " cannot be given there: sim_rfb's rosbridge server has no authentication, "
             "so any local user could drive the robot (use ros.connect: each session dials out to the lab)";
    }
    if (flag == "--robot-control") {
      return "session_args: --robot-control is set by sim_manager from the link's robot_control or ros.robot_control "
             "and cannot be given there";
    }
    if (flag.rfind("--ros", 0) == 0) {
      return "session_args: " + flag + " is set by sim_manager from the ros section and cannot be given there";
    }
    if (flag == "--allow-origin") {
      return "session_args: --allow-origin cannot be given there: sessions are reached only through sim_manager's "
             "relay, which checks the Origin itself (see frame_origins)";
    }
    // Where the setting belongs instead, for those that have a place.
    const std::string where = flag == "--codec"      ? " (use the codec setting)"
                              : flag == "--scenario" ? " (use the scenarios setting and the link's scenario)"
                              : flag == "--seed"     ? " (the link's seed parameter sets it)"
                                                     : "";
    return "session_args: " + flag + " is set by sim_manager for every session and cannot be given there" + where;
  }
  return "";
}

SessionRos session_ros(const ManagerConfig& config, const StartRequest& request, std::int64_t session_id) {
  SessionRos ros;
  const auto asked = std::find_if(request.overrides.begin(), request.overrides.end(),
                                  [](const auto& override_) { return override_.first == "robot_control"; });
  if (asked != request.overrides.end()) ros.robot_control = asked->second;
  // A legacy program gets the link's value as {robot_control}, and what it does with it is its own.
  if (config.session_kind != SessionKind::kSimRfb) return ros;
  const auto facts = std::find_if(config.scenario_facts.begin(), config.scenario_facts.end(),
                                  [&request](const ScenarioFacts& f) { return f.name == request.scenario; });
  // Only a scenario known to have a robot: without one there is nothing to drive, and a scenario whose file
  // the manager did not find is left as it was.
  if (facts == config.scenario_facts.end() || !facts->has_robot) return ros;
  const bool dials_out = !config.ros.connect.empty();
  // The link's choice, else the ros section's, else the scenario's own `robot.control`.
  if (ros.robot_control.empty()) ros.robot_control = dials_out ? config.ros.robot_control : "";
  if (ros.robot_control.empty()) ros.robot_control = facts->robot_control;
  if (dials_out) {
    // Hosts of a cluster number their sessions each from 1, and may share one lab: their names carry the host.
    const std::string host = config.cluster_peers.empty() ? std::string() : config.host_id;
    ros.ros_namespace = config.ros.ros_namespace + "/" + ros_session_name(session_id, host);
  }
  return ros;
}

std::string ros_request_problem(const ManagerConfig& config, const StartRequest& request) {
  // A watcher's session replays the robot as it was recorded: nothing drives it.
  if (config.session_kind != SessionKind::kSimRfb || request.condition == "video") return "";
  const SessionRos ros = session_ros(config, request, 0);
  const bool asked = std::any_of(request.overrides.begin(), request.overrides.end(), [](const auto& override_) {
    return override_.first == "robot_control" && override_.second == "external";
  });
  // A scenario whose own robot.control is external, on a server that does not dial out: nothing would drive it.
  if (!asked && ros.robot_control == "external" && ros.ros_namespace.empty()) {
    return "scenario " + request.scenario + " puts its robot under external control (robot.control), but this "
           "server has no connection to a lab's ROS (ros.connect), so nothing would drive it; give the link "
           "robot_control=builtin, or configure ros:";
  }
  if (!asked || !ros.ros_namespace.empty()) return "";
  if (config.ros.connect.empty()) {
    return "robot_control external is not offered here: this server has no connection to a lab's ROS (ros.connect), "
           "so nothing would drive the robot";
  }
  return "robot_control external is not offered for scenario " + request.scenario +
         ": sim_manager did not find its file, so it cannot tell whether it has a robot";
}

std::vector<std::string> session_arguments(const ManagerConfig& config, const StartRequest& request,
                                           const LaunchContext& context) {
  const std::string scenario = scenario_argument(config.scenarios, request.scenario);
  if (config.session_kind == SessionKind::kRfb) return expand_template(config, request, context, scenario);
  if (config.session_kind == SessionKind::kX11) {
    std::vector<std::string> args = {"--rfb-socket", context.unix_socket, "--xauthority", context.xauthority,
                                     "--geometry", std::to_string(config.x11.width) + "x" + std::to_string(config.x11.height),
                                     "--depth", std::to_string(config.x11.depth), "--xvnc", config.x11.xvnc,
                                     "--ready-fd", std::to_string(kReadyFd), "--", config.session_command};
    const std::vector<std::string> program_args = expand_template(config, request, context, scenario);
    args.insert(args.end(), program_args.begin(), program_args.end());
    return args;
  }
  // The config's extra arguments first: sim_rfb takes the last of a repeated flag, so everything the
  // manager and the link set below wins, whatever the config holds.
  const bool replay = !context.replay_source.empty();
  std::vector<std::string> args = replay ? without_world_flags(config.session_args) : config.session_args;
  // A unix socket only the manager's user can open: another local user cannot reach a participant's session.
  if (context.unix_socket.empty()) {
    args.insert(args.end(), {"--port", "0", "--bind", "127.0.0.1"});
  } else {
    args.insert(args.end(), {"--unix-socket", context.unix_socket});
  }
  args.insert(args.end(), {"--rfb-only", "--ready-fd", std::to_string(kReadyFd)});
  if (replay) {
    // A watcher's session: the recording's world as it was (its scenario, seed, poses, robot), view-only.
    args.insert(args.end(), {"--replay", context.replay_source, "--yoked-to", std::to_string(context.yoked_to)});
    return with_session_record(config, request, context, std::move(args));
  }
  args.insert(args.end(), {"--scenario", scenario, "--seed", std::to_string(context.seed)});
  for (const auto& [name, value] : request.overrides) {
    const auto param = std::find_if(kOverrideParams.begin(), kOverrideParams.end(),
                                    [&name = name](const OverrideParam& p) { return name == p.name; });
    args.emplace_back(param->flag);
    args.push_back(value);
  }
  // The lab's rosbridge: the session dials out under a namespace of its own; the link's robot_control (above)
  // or else the section's default says who drives. Never --rosbridge-port (kManagerFlags says why).
  const SessionRos ros = session_ros(config, request, context.session_id);
  if (!ros.ros_namespace.empty()) {
    const bool asked = std::any_of(request.overrides.begin(), request.overrides.end(),
                                   [](const auto& override_) { return override_.first == "robot_control"; });
    if (!asked) args.insert(args.end(), {"--robot-control", ros.robot_control});
    args.insert(args.end(), {"--rosbridge-connect", config.ros.connect, "--ros-namespace", ros.ros_namespace,
                             "--cmd-vel-type", config.ros.cmd_vel_type});
    if (!config.ros.token_file.empty()) args.insert(args.end(), {"--rosbridge-token-file", config.ros.token_file});
    if (!config.ros.ca_file.empty()) args.insert(args.end(), {"--rosbridge-ca", config.ros.ca_file});
  }
  return with_session_record(config, request, context, std::move(args));
}

std::string parameters_json(const StartRequest& request, std::uint64_t seed) {
  std::string json = "{\"uid\":\"" + json_escape(request.uid) + "\",\"scenario\":\"" + json_escape(request.scenario) +
                     "\",\"seed\":\"" + std::to_string(seed) + "\"";
  for (const auto& [name, value] : request.overrides) {
    json += ",\"" + json_escape(name) + "\":\"" + json_escape(value) + "\"";
  }
  if (!request.code_success.empty()) json += ",\"t1\":\"" + json_escape(request.code_success) + "\"";
  if (!request.code_timeout.empty()) json += ",\"t2\":\"" + json_escape(request.code_timeout) + "\"";
  // A video link's condition; its yoke_uid is left out: a watcher's records never name the walker's uid.
  if (request.condition != "interactive") json += ",\"condition\":\"" + json_escape(request.condition) + "\"";
  if (!request.yoke_uid.empty()) json += ",\"yoke_pinned\":true";
  return json + "}";
}

}  // namespace rfbsim::manager
