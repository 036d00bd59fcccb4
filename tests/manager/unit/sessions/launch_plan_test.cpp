// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <algorithm>

#include "sessions/launch_plan.hpp"

using rfbsim::manager::LaunchContext;
using rfbsim::manager::ManagerConfig;
using rfbsim::manager::parameters_json;
using rfbsim::manager::session_arguments;
using rfbsim::manager::SessionKind;
using rfbsim::manager::StartRequest;

using Args = std::vector<std::string>;

namespace {

StartRequest request(const std::string& scenario) {
  StartRequest r;
  r.uid = "p01";
  r.scenario = scenario;
  return r;
}

}  // namespace

TEST_CASE("sim_rfb gets its fixed flags, the scenario, the seed and where to record the session") {
  ManagerConfig config;
  const LaunchContext context{7, 0, "/data/p01-1", ""};
  CHECK(session_arguments(config, request("lab"), context) ==
        Args{"--port", "0", "--bind", "127.0.0.1", "--rfb-only", "--ready-fd", "3", "--scenario", "lab", "--seed", "7",
             "--proxy-protocol", "--data-dir", "/data/p01-1", "--uid", "p01", "--codec", "auto"});
}

TEST_CASE("with a unix socket sim_rfb is told the socket instead of a port and an address") {
  ManagerConfig config;
  const LaunchContext context{7, 0, "/data/p01-1", "/tmp/rfbsim-manager-x/1.sock"};
  CHECK(session_arguments(config, request("lab"), context) ==
        Args{"--unix-socket", "/tmp/rfbsim-manager-x/1.sock", "--rfb-only", "--ready-fd", "3", "--scenario", "lab",
             "--seed", "7", "--proxy-protocol", "--data-dir", "/data/p01-1", "--uid", "p01", "--codec", "auto"});
}

TEST_CASE("sim_rfb gets the configured codec, and only sim_rfb does") {
  ManagerConfig config;
  config.codec = "h264";
  const LaunchContext context{7, 0, "/data/p01-1", ""};
  const Args args = session_arguments(config, request("lab"), context);
  const auto codec = std::find(args.begin(), args.end(), "--codec");
  REQUIRE(codec != args.end());
  REQUIRE(codec + 1 != args.end());
  CHECK(*(codec + 1) == "h264");
  CHECK(std::count(args.begin(), args.end(), "--codec") == 1);
  // A legacy RFB program gets its own argument list and nothing else.
  config.session_kind = SessionKind::kRfb;
  config.session_args = {"--rfbport", "{port}"};
  CHECK(session_arguments(config, request("lab"), LaunchContext{7, 5901, "/d", ""}) == Args{"--rfbport", "5901"});
}

TEST_CASE("sim_rfb gets the link's completion codes, each only when the link has it") {
  ManagerConfig config;
  const LaunchContext context{7, 0, "/data/p01-1", ""};
  StartRequest r = request("lab");
  r.code_success = "OK-123";
  r.code_timeout = "LATE_9";
  Args args = session_arguments(config, r, context);
  CHECK(Args(args.end() - 4, args.end()) == Args{"--code-success", "OK-123", "--code-timeout", "LATE_9"});
  r.code_success.clear();
  args = session_arguments(config, r, context);
  CHECK(Args(args.end() - 2, args.end()) == Args{"--code-timeout", "LATE_9"});
  CHECK(std::find(args.begin(), args.end(), "--code-success") == args.end());
  CHECK(parameters_json(request("lab"), 7).find("t1") == std::string::npos);
  r.code_success = "OK-123";
  CHECK(parameters_json(r, 7) == R"({"uid":"p01","scenario":"lab","seed":"7","t1":"OK-123","t2":"LATE_9"})");
}

TEST_CASE("sim_rfb gets the configured extra arguments first, then one flag per override") {
  ManagerConfig config;
  config.scenarios = {"warehouse", "lab=/srv/scenarios/lab.yaml"};
  config.session_args = {"--width", "1280", "--fps=30"};
  StartRequest r = request("lab");
  r.overrides = {{"avatar_start", "1.5,-2,0.25"}, {"robot_goal", "dock"}, {"crowd", "12"}};
  const LaunchContext context{18446744073709551615ULL, 0, "/data/p01-1", ""};
  CHECK(session_arguments(config, r, context) == Args{"--width",
                                                       "1280",
                                                       "--fps=30",
                                                       "--port",
                                                       "0",
                                                       "--bind",
                                                       "127.0.0.1",
                                                       "--rfb-only",
                                                       "--ready-fd",
                                                       "3",
                                                       "--scenario",
                                                       "/srv/scenarios/lab.yaml",
                                                       "--seed",
                                                       "18446744073709551615",
                                                       "--avatar-start",
                                                       "1.5,-2,0.25",
                                                       "--robot-goal",
                                                       "dock",
                                                       "--crowd",
                                                       "12",
                                                       "--proxy-protocol",
                                                       "--data-dir",
                                                       "/data/p01-1",
                                                       "--uid",
                                                       "p01",
                                                       "--codec",
                                                       "auto"});
}

TEST_CASE("the manager's flags and the link's come after the config's, so that sim_rfb's last-wins parsing keeps "
          "them") {
  ManagerConfig config;
  // A study-wide default the link may override, and a time limit the link has no say in.
  config.session_args = {"--avatar-start", "door", "--time-limit", "90"};
  StartRequest r = request("lab");
  r.overrides = {{"avatar_start", "1,2,0"}};
  const Args args = session_arguments(config, r, LaunchContext{7, 0, "/data/p01-1", ""});
  const auto last_value = [&](const std::string& flag) {
    const auto at = std::find(args.rbegin(), args.rend(), flag);
    REQUIRE(at != args.rend());
    REQUIRE(at != args.rbegin());
    return *(at - 1);
  };
  CHECK(Args(args.begin(), args.begin() + 4) == Args{"--avatar-start", "door", "--time-limit", "90"});
  CHECK(last_value("--avatar-start") == "1,2,0");
  CHECK(last_value("--time-limit") == "90");
  CHECK(last_value("--bind") == "127.0.0.1");
  CHECK(last_value("--data-dir") == "/data/p01-1");
}

TEST_CASE("session_args may not name a flag the manager sets for sim_rfb") {
  using rfbsim::manager::kManagerFlags;
  using rfbsim::manager::session_args_problem;
  CHECK(session_args_problem({}, SessionKind::kSimRfb).empty());
  CHECK(session_args_problem({"--width", "1280", "--fps=30", "--time-limit", "90", "--debug-overlay"},
                             SessionKind::kSimRfb)
            .empty());
  CHECK(session_args_problem({"--width", "640", "--bind", "0.0.0.0"}, SessionKind::kSimRfb) ==
        "session_args: --bind is set by sim_manager for every session and cannot be given there");
  CHECK(session_args_problem({"--port=5900"}, SessionKind::kSimRfb) ==
        "session_args: --port is set by sim_manager for every session and cannot be given there");
  CHECK(session_args_problem({"--data-dir=/tmp/x"}, SessionKind::kSimRfb) ==
        "session_args: --data-dir is set by sim_manager for every session and cannot be given there");
  CHECK(session_args_problem({"--codec", "jpeg"}, SessionKind::kSimRfb) ==
        "session_args: --codec is set by sim_manager for every session and cannot be given there (use the codec "
        "setting)");
  CHECK(session_args_problem({"--seed", "3"}, SessionKind::kSimRfb) ==
        "session_args: --seed is set by sim_manager for every session and cannot be given there (the link's seed "
        "parameter sets it)");
  CHECK(session_args_problem({"--allow-origin", "*"}, SessionKind::kSimRfb) ==
        "session_args: --allow-origin cannot be given there: sessions are reached only through sim_manager's relay, "
        "which checks the Origin itself (see frame_origins)");
  // The first offender is named.
  CHECK(session_args_problem({"--uid", "x", "--proxy-protocol"}, SessionKind::kSimRfb) ==
        "session_args: --uid is set by sim_manager for every session and cannot be given there");
  // Every flag of the list, alone and with a value attached, is refused.
  for (const std::string& flag : kManagerFlags) {
    INFO(flag);
    CHECK_FALSE(session_args_problem({flag}, SessionKind::kSimRfb).empty());
    CHECK_FALSE(session_args_problem({flag + "=1"}, SessionKind::kSimRfb).empty());
  }
  for (const std::string flag :
       {"--bind", "--port", "--data-dir", "--ready-fd", "--rfb-only", "--proxy-protocol", "--uid", "--unix-socket",
        "--web-root"}) {
    CHECK(std::find(kManagerFlags.begin(), kManagerFlags.end(), flag) != kManagerFlags.end());
  }
  // Only the whole flag counts: longer names and values that merely contain one are fine.
  CHECK(session_args_problem({"--bindings", "--portal", "x--port", "--web-rooted"}, SessionKind::kSimRfb).empty());
  // An rfb program's template is its own: its --port is the program's flag, not sim_rfb's.
  CHECK(session_args_problem({"--port", "{port}", "--bind=127.0.0.1"}, SessionKind::kRfb).empty());
}

TEST_CASE("an rfb program gets its argument template with the placeholders replaced") {
  ManagerConfig config;
  config.session_kind = SessionKind::kRfb;
  config.scenarios = {"warehouse=/srv/w.yaml", "lab"};
  config.session_args = {"--listen=127.0.0.1:{port}", "{port}", "--log", "{data_dir}/{uid}-{seed}.log",
                         "--scenario", "{scenario}", "{port}{port}", "{unknown}", "plain"};
  StartRequest r = request("warehouse");
  r.overrides = {{"crowd", "3"}};  // an override the template does not name is not added to it
  const LaunchContext context{42, 5907, "/data/p01-3", ""};
  CHECK(session_arguments(config, r, context) == Args{"--listen=127.0.0.1:5907", "5907", "--log",
                                                       "/data/p01-3/p01-42.log", "--scenario", "/srv/w.yaml",
                                                       "59075907", "{unknown}", "plain"});
}

TEST_CASE("an rfb program gets the link's validated overrides and codes through their placeholders") {
  ManagerConfig config;
  config.session_kind = SessionKind::kRfb;
  config.session_args = {"--port={port}",         "--start",        "{avatar_start}", "--goal={avatar_goal}",
                         "--robot={robot_start}", "{robot_goal}",   "--people",       "{crowd}",
                         "--ok",                  "{t1}",           "--late={t2}"};
  StartRequest r = request("lab");
  r.overrides = {{"avatar_start", "1.5,-2,0.25"}, {"avatar_goal", "door"}, {"robot_start", "dock"},
                 {"robot_goal", "0,0,0"},         {"crowd", "12"}};
  r.code_success = "C1A2B3";
  r.code_timeout = "T-9_x";
  const LaunchContext context{1, 5900, "/data/p01-1", ""};
  CHECK(session_arguments(config, r, context) == Args{"--port=5900", "--start", "1.5,-2,0.25", "--goal=door",
                                                       "--robot=dock", "0,0,0", "--people", "12", "--ok", "C1A2B3",
                                                       "--late=T-9_x"});
  // What the link does not carry is empty: the template decides how its program takes that.
  CHECK(session_arguments(config, request("lab"), context) ==
        Args{"--port=5900", "--start", "", "--goal=", "--robot=", "", "--people", "", "--ok", "", "--late="});
}

TEST_CASE("a replaced value is not searched for placeholders again") {
  ManagerConfig config;
  config.session_kind = SessionKind::kRfb;
  config.session_args = {"{data_dir}:{port}"};
  const LaunchContext context{1, 5900, "/data/{port}", ""};
  CHECK(session_arguments(config, request("lab"), context) == Args{"/data/{port}:5900"});
  // Also a value replaced before the placeholder it contains would be.
  config.scenarios = {"lab=/srv/{uid}-{seed}.yaml"};
  config.session_args = {"{scenario}", "{port}"};
  CHECK(session_arguments(config, request("lab"), context) == Args{"/srv/{uid}-{seed}.yaml", "5900"});
}

TEST_CASE("the link's parameters as JSON") {
  StartRequest r = request("lab");
  CHECK(parameters_json(r, 7) == R"({"uid":"p01","scenario":"lab","seed":"7"})");
  r.overrides = {{"avatar_start", "1.5,-2,0.25"}, {"crowd", "12"}};
  CHECK(parameters_json(r, 18446744073709551615ULL) ==
        R"({"uid":"p01","scenario":"lab","seed":"18446744073709551615","avatar_start":"1.5,-2,0.25","crowd":"12"})");
}

TEST_CASE("the JSON escapes what it writes") {
  StartRequest r = request("a\"b");
  r.uid = "x\\y";
  CHECK(parameters_json(r, 0) == R"({"uid":"x\\y","scenario":"a\"b","seed":"0"})");
}

// --- ROS (issue 20): the link's robot_control and the config's ros section ---

namespace {

using rfbsim::manager::ros_request_problem;
using rfbsim::manager::ScenarioFacts;
using rfbsim::manager::session_ros;

// A config offering "depot" (a robot), "hall" (no robot) and "lost" (no file found: no facts).
ManagerConfig ros_config() {
  ManagerConfig config;
  config.scenarios = {"depot", "hall", "lost"};
  ScenarioFacts depot;
  depot.name = "depot";
  depot.has_robot = true;
  ScenarioFacts hall;
  hall.name = "hall";
  config.scenario_facts = {depot, hall};
  return config;
}

// The arguments after --seed N and before --proxy-protocol: the overrides and ROS's flags.
Args middle(const Args& args) {
  const auto seed = std::find(args.begin(), args.end(), "--seed");
  REQUIRE(std::distance(seed, args.end()) >= 2);
  const auto proxy = std::find(seed + 2, args.end(), "--proxy-protocol");
  REQUIRE(proxy != args.end());
  return Args(seed + 2, proxy);
}

}  // namespace

TEST_CASE("the link's robot_control reaches sim_rfb as --robot-control, with or without ROS") {
  ManagerConfig config = ros_config();
  StartRequest r = request("depot");
  r.overrides = {{"robot_goal", "dock"}, {"robot_control", "builtin"}};
  const LaunchContext context{7, 0, "/data/p01-1", "", 12};
  CHECK(middle(session_arguments(config, r, context)) == Args{"--robot-goal", "dock", "--robot-control", "builtin"});
  CHECK(parameters_json(r, 7) ==
        R"({"uid":"p01","scenario":"depot","seed":"7","robot_goal":"dock","robot_control":"builtin"})");
  // Without a ros section nothing else is added, and a link without the setting is as before.
  CHECK(middle(session_arguments(config, request("depot"), context)).empty());
  CHECK(session_ros(config, request("depot"), 12).robot_control == "builtin");
  CHECK(session_ros(config, request("depot"), 12).ros_namespace.empty());
  CHECK(session_ros(config, request("hall"), 12).robot_control.empty());
}

TEST_CASE("the link's camera reaches sim_rfb as --camera, last of the overrides, and the index's parameters") {
  const ManagerConfig config = ros_config();
  StartRequest r = request("depot");
  r.overrides = {{"crowd", "3"}, {"camera", "first_person"}};
  const LaunchContext context{7, 0, "/data/p01-1", "", 12};
  CHECK(middle(session_arguments(config, r, context)) == Args{"--crowd", "3", "--camera", "first_person"});
  CHECK(parameters_json(r, 7) == R"({"uid":"p01","scenario":"depot","seed":"7","crowd":"3","camera":"first_person"})");
}

TEST_CASE("with a ros section a robot scenario's session dials out to the lab under its own namespace") {
  ManagerConfig config = ros_config();
  config.ros.connect = "wss://ros.lab.example.org:9090/";
  config.ros.token_file = "/etc/rfbsim/rosbridge.token";
  config.ros.ca_file = "/etc/rfbsim/lab-ca.pem";
  config.ros.robot_control = "external";
  const LaunchContext context{7, 0, "/data/p01-12", "", 12};
  const Args args = session_arguments(config, request("depot"), context);
  CHECK(middle(args) == Args{"--robot-control", "external", "--rosbridge-connect", "wss://ros.lab.example.org:9090/",
                             "--ros-namespace", "/rfbsim/s_12", "--cmd-vel-type", "twist", "--rosbridge-token-file",
                             "/etc/rfbsim/rosbridge.token", "--rosbridge-ca", "/etc/rfbsim/lab-ca.pem"});
  // Never sim_rfb's own rosbridge port: it has no authentication.
  CHECK(std::find(args.begin(), args.end(), "--rosbridge-port") == args.end());
  CHECK(std::find(args.begin(), args.end(), "--rosbridge-bind") == args.end());
  const auto ros = session_ros(config, request("depot"), 12);
  CHECK(ros.ros_namespace == "/rfbsim/s_12");
  CHECK(ros.robot_control == "external");

  // The link's robot_control wins over the section's default, and is given once.
  StartRequest r = request("depot");
  r.overrides = {{"robot_control", "builtin"}};
  const Args chosen = session_arguments(config, r, context);
  CHECK(std::count(chosen.begin(), chosen.end(), "--robot-control") == 1);
  CHECK(middle(chosen).at(1) == "builtin");
  CHECK(session_ros(config, r, 12).robot_control == "builtin");

  // Without optional files, only the connection and the namespace; the default control is builtin.
  config.ros.token_file.clear();
  config.ros.ca_file.clear();
  config.ros.robot_control = "builtin";
  config.ros.ros_namespace = "/lab/study_3";
  config.ros.cmd_vel_type = "twist_stamped";
  CHECK(middle(session_arguments(config, request("depot"), {7, 0, "/d", "", 3})) ==
        Args{"--robot-control", "builtin", "--rosbridge-connect", "wss://ros.lab.example.org:9090/", "--ros-namespace",
             "/lab/study_3/s_3", "--cmd-vel-type", "twist_stamped"});
}

TEST_CASE("a scenario without a robot, or one whose file was not found, gets no ROS") {
  ManagerConfig config = ros_config();
  config.ros.connect = "ws://127.0.0.1:9090";
  config.ros.robot_control = "external";
  for (const char* scenario : {"hall", "lost"}) {
    INFO(scenario);
    CHECK(middle(session_arguments(config, request(scenario), {7, 0, "/d", "", 5})).empty());
    CHECK(session_ros(config, request(scenario), 5).ros_namespace.empty());
    CHECK(session_ros(config, request(scenario), 5).robot_control.empty());
  }
}

TEST_CASE("in a cluster a session's ROS name carries its host, whose ids number sessions each from 1") {
  ManagerConfig config = ros_config();
  config.ros.connect = "wss://ros.lab.example.org/";
  config.host_id = "h-2";
  CHECK(session_ros(config, request("depot"), 12).ros_namespace == "/rfbsim/s_12");
  config.cluster_peers = {{"h-1", "10.0.0.1", 7000}, {"h-2", "10.0.0.2", 7000}, {"h3", "10.0.0.3", 7000}};
  CHECK(session_ros(config, request("depot"), 12).ros_namespace == "/rfbsim/s_12_h_2");
}

TEST_CASE("a link asking for external control is refused where nothing would drive the robot") {
  ManagerConfig config = ros_config();
  StartRequest r = request("depot");
  r.overrides = {{"robot_control", "external"}};
  CHECK(ros_request_problem(config, r) ==
        "robot_control external is not offered here: this server has no connection to a lab's ROS (ros.connect), so "
        "nothing would drive the robot");
  config.ros.connect = "wss://ros.lab.example.org/";
  CHECK(ros_request_problem(config, r).empty());
  r.scenario = "lost";
  CHECK(ros_request_problem(config, r) ==
        "robot_control external is not offered for scenario lost: sim_manager did not find its file, so it cannot "
        "tell whether it has a robot");
  // builtin, or no setting, is always fine.
  r.overrides = {{"robot_control", "builtin"}};
  CHECK(ros_request_problem(config, r).empty());
  CHECK(ros_request_problem(ros_config(), request("depot")).empty());
  // A legacy program's template takes the value as it is.
  ManagerConfig legacy;
  legacy.session_kind = SessionKind::kRfb;
  r.overrides = {{"robot_control", "external"}};
  CHECK(ros_request_problem(legacy, r).empty());
}

TEST_CASE("a scenario's own robot.control is the default, and is refused where nothing would drive the robot") {
  ManagerConfig config = ros_config();
  ScenarioFacts drone;
  drone.name = "drone";
  drone.has_robot = true;
  drone.robot_control = "external";
  config.scenarios.push_back("drone");
  config.scenario_facts.push_back(drone);
  // No ros section: a link that says nothing would start a robot nobody can drive; builtin is fine.
  CHECK(ros_request_problem(config, request("drone")).find("puts its robot under external control") != std::string::npos);
  StartRequest builtin = request("drone");
  builtin.overrides = {{"robot_control", "builtin"}};
  CHECK(ros_request_problem(config, builtin).empty());
  CHECK(session_ros(config, builtin, 3).robot_control == "builtin");
  // With a ros section that leaves control to the scenarios, the scenario's external reaches sim_rfb.
  config.ros.connect = "wss://ros.lab.example.org:9090/";
  CHECK(ros_request_problem(config, request("drone")).empty());
  CHECK(session_ros(config, request("drone"), 3).robot_control == "external");
  const Args args = middle(session_arguments(config, request("drone"), {7, 0, "/d", "", 3}));
  REQUIRE(args.size() >= 2);
  CHECK(args.at(0) == "--robot-control");
  CHECK(args.at(1) == "external");
  CHECK(session_ros(config, request("depot"), 3).robot_control == "builtin");
  // The section's own default wins over the scenario's.
  config.ros.robot_control = "builtin";
  CHECK(session_ros(config, request("drone"), 3).robot_control == "builtin");
}

TEST_CASE("an rfb program gets the link's robot_control as {robot_control}") {
  ManagerConfig config;
  config.session_kind = SessionKind::kRfb;
  config.session_args = {"--port={port}", "--control={robot_control}"};
  StartRequest r = request("lab");
  r.overrides = {{"robot_control", "external"}};
  CHECK(session_arguments(config, r, {1, 5900, "/d", "", 1}) == Args{"--port=5900", "--control=external"});
  CHECK(session_arguments(config, request("lab"), {1, 5900, "/d", "", 1}) == Args{"--port=5900", "--control="});
}

TEST_CASE("session_args may not open sim_rfb's rosbridge server nor set ROS's flags") {
  using rfbsim::manager::session_args_problem;
  CHECK(session_args_problem({"--rosbridge-port", "9090"}, SessionKind::kSimRfb) ==
        "session_args: --rosbridge-port cannot be given there: sim_rfb's rosbridge server has no authentication, so "
        "any local user could drive the robot (use ros.connect: each session dials out to the lab)");
  CHECK(session_args_problem({"--rosbridge-bind=0.0.0.0"}, SessionKind::kSimRfb) ==
        "session_args: --rosbridge-bind cannot be given there: sim_rfb's rosbridge server has no authentication, so "
        "any local user could drive the robot (use ros.connect: each session dials out to the lab)");
  CHECK(session_args_problem({"--rosbridge-connect", "ws://x"}, SessionKind::kSimRfb) ==
        "session_args: --rosbridge-connect is set by sim_manager from the ros section and cannot be given there");
  CHECK(session_args_problem({"--robot-control", "external"}, SessionKind::kSimRfb) ==
        "session_args: --robot-control is set by sim_manager from the link's robot_control or ros.robot_control and "
        "cannot be given there");
  for (const char* flag : {"--rosbridge-token-file", "--rosbridge-ca", "--ros-namespace"}) {
    CHECK_FALSE(session_args_problem({flag, "x"}, SessionKind::kSimRfb).empty());
  }
}

TEST_CASE("an x11 session runs rfbsim_x11_session with its display and the program's expanded template") {
  ManagerConfig config;
  config.session_kind = SessionKind::kX11;
  config.session_command = "/usr/bin/glxgears";
  config.scenarios = {};
  config.x11.width = 640;
  config.x11.height = 480;
  config.session_args = {"-geometry", "640x480+0+0", "--log={data_dir}/{uid}.log", "{seed}", "{crowd}"};
  StartRequest r = request("");
  LaunchContext context{7, 0, "/data/3-p01", "/run/rfbsim-x/3.sock"};
  context.xauthority = "/run/rfbsim-x/3.xauth";
  CHECK(session_arguments(config, r, context) ==
        Args{"--rfb-socket", "/run/rfbsim-x/3.sock", "--xauthority", "/run/rfbsim-x/3.xauth", "--geometry", "640x480",
             "--depth", "24", "--xvnc", "/usr/bin/Xvnc", "--ready-fd", "3", "--", "/usr/bin/glxgears", "-geometry",
             "640x480+0+0", "--log=/data/3-p01/p01.log", "7", ""});
}

TEST_CASE("a watcher's sim_rfb replays the source's folder, with no world of its own and no timeout code") {
  ManagerConfig config;
  // A walker's time limit and crowd in the study's extra arguments would make --replay refuse to start.
  config.session_args = {"--time-limit", "30", "--quality", "70", "--crowd=4", "--end-grace", "5"};
  StartRequest r = request("lab");
  r.condition = "video";
  r.code_success = "VID-1";
  r.code_timeout = "LATE-1";
  LaunchContext context{7, 0, "/data/sessions/9-p01", "/run/s/9.sock"};
  context.replay_source = "/data/sessions/3-a1";
  context.yoked_to = 3;
  CHECK(session_arguments(config, r, context) ==
        Args{"--quality", "70", "--end-grace", "5", "--unix-socket", "/run/s/9.sock", "--rfb-only", "--ready-fd", "3",
             "--replay", "/data/sessions/3-a1", "--yoked-to", "3", "--proxy-protocol", "--data-dir",
             "/data/sessions/9-p01", "--uid", "p01", "--codec", "auto", "--code-success", "VID-1"});
  // The index's parameters say video, and never name a pinned walker.
  r.yoke_uid = "a1";
  CHECK(parameters_json(r, 7) == R"({"uid":"p01","scenario":"lab","seed":"7","t1":"VID-1","t2":"LATE-1",)"
                                 R"("condition":"video","yoke_pinned":true})");
}
