// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb's command line: each option declared once with CLI11, from which parsing and --help follow.
#include "app/options.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>

#include "cli/command_line.hpp"
#include "contract/replay_flags.hpp"
#include "contract/task_bounds.hpp"
#include "contract/validators.hpp"

namespace rfbsim::sim {

namespace {

// The values sim_manager also checks before it passes them here: one rule each, in the contract
// (contract/validators.hpp), so that the two programs cannot disagree.
using contract::is_identifier;      // participant ids and completion codes
using contract::looks_like_origin;  // --allow-origin's shape; librfbsim checks the host and port when it starts

// A ROS graph name used as a topic prefix, up to the contract's kMaxRosName (room for sim_manager's root and
// its "/s_<id>_<host>").
bool is_ros_namespace(const std::string& text) { return contract::is_ros_name(text); }

// ws://host[:port][/path] or wss://...: the shape only (the client parses it fully when it starts). No user info
// and no query: credentials go in --rosbridge-token-file, never in a URL that logs, session.json and ps show.
bool looks_like_websocket_url(const std::string& text) { return contract::websocket_url_problem(text).empty(); }

}  // namespace

namespace {

// Declares every option of sim_rfb on `app`, bound to `o`'s fields (whose initial values are the defaults).
void declare_sim_options(CLI::App& app, SimOptions& o) {
  using cli::in_range;
  using cli::non_empty;
  using cli::satisfies;
  cli::configure(app);
  app.add_flag("-h,--help", o.help, "print this help and exit");

  // Where and how the server listens.
  app.add_option("--port", o.port, "TCP port for the page, WebSocket and RFB; 0 = any free port")
      ->type_name("N")->capture_default_str()->transform(in_range(0, 65535));
  app.add_option("--bind", o.bind, "numeric address to listen on")
      ->type_name("ADDR")->capture_default_str()->check(non_empty());
  app.add_option("--unix-socket", o.unix_socket,
                 "listen on unix socket P (mode 0600: only this user may connect) instead of TCP;\n"
                 "replaces --port and --bind (giving either is an error); a stale socket there is\n"
                 "replaced, the file is removed at exit")
      ->type_name("P")
      // The path goes into the one-line ready message: no line breaks or other control characters.
      ->check(satisfies([](const std::string& v) {
        return !v.empty() && std::none_of(v.begin(), v.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; });
      }));
  app.add_option("--max-clients", o.max_clients, "viewers at once")
      ->type_name("N")->capture_default_str()->transform(in_range(1, 64));
  app.add_option("--web-root", o.web_root, "directory holding the participant page (default: the built page)")
      ->type_name("DIR")->check(non_empty());
  app.add_flag("--rfb-only", o.rfb_only,
               "serve RFB only (raw and over WebSocket): no page, no /status.json; a raw RFB\n"
               "client is then served after 0.1 s instead of 0.5 s (at once behind --proxy-protocol)");
  app.add_flag("--proxy-protocol", o.proxy_protocol,
               "each connection begins with a PROXY protocol v1 line naming the real client,\n"
               "as sim_manager's relay sends it (for a trusted relay only: never on a port\n"
               "that others reach)");
  app.add_option("--allow-origin", o.allowed_origins,
                 "also accept WebSocket upgrades from pages at origin O (scheme://host[:port], or *\n"
                 "for any page); repeatable. Without it only this server's own page and loopback\n"
                 "pages (http(s)://127.0.0.1, localhost, [::1]) may open the stream; others get 403")
      ->type_name("O")->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(satisfies(looks_like_origin, "scheme://host[:port] with http or https, or *"));
  app.add_option("--ready-fd", o.ready_fd,
                 "once listening, write 'ready PORT' ('ready unix PATH' with --unix-socket) and a\n"
                 "newline to file descriptor N (3 or above, e.g. a pipe from the parent) and keep it\n"
                 "open: later lines report the viewers' stream about once a second ('stream\n"
                 "codec=tight rtt_ms=12.5 fps=29.8 quality=80 clients=1') and the task's outcome\n"
                 "('outcome completed' or 'outcome timeout'); exit 1 if the ready line cannot be written")
      // 0, 1 and 2 are stdin, stdout and stderr: writing the ready line there is surely a mistake.
      ->type_name("N")->transform(in_range(3, INT_MAX));

  // The picture.
  app.add_option("--width", o.width, "frame width in pixels")
      ->type_name("W")->capture_default_str()->transform(in_range(160, 3840));
  app.add_option("--height", o.height, "frame height in pixels")
      ->type_name("H")->capture_default_str()->transform(in_range(120, 2160));
  app.add_option("--fps", o.fps, "frames per second while someone watches")
      ->type_name("F")->capture_default_str()->transform(in_range(1, 120));
  app.add_option("--quality", o.jpeg_quality, "JPEG quality: the most any viewer gets (a viewer may ask for less)")
      ->type_name("Q")->capture_default_str()->transform(in_range(1, 100));
  cli::one_of(app.add_option("--codec", o.codec,
                             "picture encoding: auto (Tight JPEG, H.264 for a client that offers it once its\n"
                             "link cannot carry the frame rate), jpeg (Tight JPEG always) or h264 (H.264 for\n"
                             "every client that offers it, such as noVNC 1.6+ over https)")
                  ->capture_default_str(),
              {"auto", "jpeg", "h264"});
  cli::one_of(app.add_option("--egl", o.egl_platform, "EGL platform (auto: GPU device, else Mesa surfaceless)")
                  ->capture_default_str(),
              {"auto", "device", "surfaceless"});
  cli::add_log_level(app, o.log_level);
  app.add_flag("--debug-overlay", o.debug_overlay,
               "draw the robot's global path, local trajectory, goal, pose estimate and social\n"
               "cost on the floor (for developers; participants should not see it)");

  // The scenario and its overrides.
  app.add_option("--seed", o.seed, "random seed (default: the scenario's)")
      ->type_name("S")->transform(in_range<std::uint64_t>(0, UINT64_MAX));
  app.add_option("--scenario", o.scenario,
                 "scenario name (warehouse, lab) or YAML file (default: a small test room)")
      ->type_name("NAME|PATH")->check(non_empty());
  const char* point_help = "a spawn point's name or x,y,yaw in metres and radians";
  for (auto [name, field] : {std::pair{"--avatar-start", &o.avatar_start}, std::pair{"--avatar-goal", &o.avatar_goal},
                             std::pair{"--robot-start", &o.robot_start}, std::pair{"--robot-goal", &o.robot_goal}}) {
    app.add_option(name, *field, point_help)->type_name("P")->check(non_empty());
  }
  app.add_option("--crowd", o.crowd, "number of pedestrians (default: the scenario's)")
      ->type_name("N")->transform(in_range(0, 500));
  app.add_option("--time-limit", o.time_limit, "the task's time limit in seconds (default: the scenario's)")
      ->type_name("S")->transform(in_range(contract::kMinTimeLimitS, contract::kMaxTimeLimitS));
  app.add_option("--end-grace", o.end_grace,
                 "seconds the outcome and the code stay on screen before the session ends\n"
                 "(default: the scenario's end_grace)")
      ->type_name("S")->transform(in_range(contract::kMinEndGraceS, contract::kMaxEndGraceS));
  cli::one_of(app.add_option("--robot-control", o.robot_control,
                             "who drives the robot: builtin (its own navigation stack) or external (/cmd_vel over\n"
                             "rosbridge drives it; it stops 0.5 s after the last command) (default: the scenario's)"),
              {"builtin", "external"});
  cli::one_of(app.add_option("--camera", o.camera,
                             "the participant's view: third_person (behind the avatar) or first_person (from its\n"
                             "eyes, its body not drawn) (default: the scenario's camera, else third_person)"),
              {"third_person", "first_person"});

  // The study's records.
  app.add_option("--data-dir", o.data_dir,
                 "record the session there: session.json, trajectories.csv, events.jsonl\n"
                 "(docs/data.md); without it nothing is recorded")
      ->type_name("DIR")->check(non_empty());
  CLI::Option* replay = app.add_option("--replay", o.replay,
                 "show the session recorded in DIR (a --data-dir folder) at its own pace, view-only;\n"
                 "it ends with outcome 'watched' (docs/replay.md)")
      ->type_name("DIR")->check(non_empty());
  // The recording's world, as it was: options that would make another are refused beside it.
  for (const std::string_view flag : contract::kWorldFlags) replay->excludes(std::string(flag));
  app.add_option("--yoked-to", o.yoked_to,
                 "with --replay: the recorded session's id in sim_manager's index, kept in the\n"
                 "watcher's session.json as yoked_to (sim_manager sets it)")
      ->type_name("ID")->needs("--replay")->check(CLI::Range(std::int64_t{1}, std::int64_t{1} << 53));
  app.add_option("--uid", o.uid, "participant id recorded in session.json (letters, digits, - and _)")
      ->type_name("ID")->check(satisfies(is_identifier));
  const char* code_help = "completion code shown when the task is done (--code-success) or the time is up\n"
                          "(--code-timeout): 1..64 of letters, digits, - and _ (SEAN-EP's t1 and t2)";
  app.add_option("--code-success", o.code_success, code_help)->type_name("C")->check(satisfies(is_identifier));
  app.add_option("--code-timeout", o.code_timeout, code_help)->type_name("C")->check(satisfies(is_identifier));
  app.add_option("--trajectory-hz", o.trajectory_hz, "trajectory rows per second, a divisor of the tick rate 60")
      ->type_name("N")->capture_default_str()->transform(in_range(1, 60))
      ->check(satisfies([](const std::string& v) { return 60 % std::stoi(v) == 0; }));
  app.add_flag_callback("--no-mcap", [&o] { o.mcap = false; },
                        "with --data-dir, do not write session.mcap (the ROS 2 bag, docs/ros.md)");

  // ROS (docs/ros.md).
  app.add_option("--rosbridge-port", o.rosbridge_port,
                 "serve the ROS topics live over rosbridge v2 (JSON over WebSocket at /) on\n"
                 "port N (0 = any free port). Unauthenticated: keep it on loopback")
      ->type_name("N")->transform(in_range(0, 65535));
  app.add_option("--rosbridge-bind", o.rosbridge_bind, "numeric address for --rosbridge-port")
      ->type_name("ADDR")->capture_default_str()->check(non_empty());
  app.add_option("--rosbridge-connect", o.rosbridge_connect,
                 "dial out to a lab's rosbridge_server (ws:// or wss://) and publish there,\n"
                 "taking /cmd_vel from it; reconnects by itself")
      ->type_name("URL")
      ->check(satisfies(looks_like_websocket_url,
                        "ws://host[:port][/path] or wss://..., without user info or query: a token goes in "
                        "--rosbridge-token-file"));
  app.add_option("--rosbridge-token-file", o.rosbridge_token_file,
                 "send F's first line as 'Authorization: Bearer' when dialling out")
      ->type_name("F")->check(non_empty());
  app.add_option("--rosbridge-ca", o.rosbridge_ca, "extra CA certificates (PEM) to trust for wss://")
      ->type_name("F")->check(non_empty());
  app.add_option("--ros-namespace", o.ros_namespace, "put every topic under NS (e.g. /rfbsim/s1): /rfbsim/s1/scan")
      ->type_name("NS")->check(satisfies(is_ros_namespace, "a ROS name such as /rfbsim/s1"));
  // Given as a short name, kept as the message type.
  cli::one_of(app.add_option_function<std::string>(
                     "--cmd-vel-type",
                     [&o](const std::string& v) {
                       o.cmd_vel_type = v == "twist_stamped" ? "geometry_msgs/msg/TwistStamped" : "geometry_msgs/msg/Twist";
                     },
                     "twist (geometry_msgs/msg/Twist) or twist_stamped: the type --rosbridge-connect\n"
                     "subscribes to the lab's /cmd_vel with (--rosbridge-port takes both)")
                  ->default_str("twist"),
              {"twist", "twist_stamped"});
}

}  // namespace

std::string sim_usage() {
  SimOptions defaults;
  CLI::App app("An interactive robot simulation served to the browser over RFB/WebSocket.", "sim_rfb");
  declare_sim_options(app, defaults);
  return app.help();
}

ParseOutcome parse_sim_options(const std::vector<std::string>& args) {
  ParseOutcome outcome;
  SimOptions& o = outcome.options;
  CLI::App app("sim_rfb", "sim_rfb");
  declare_sim_options(app, o);
  outcome.error = cli::parse(app, args);
  if (!outcome.error.empty()) return outcome;
  // Without HTTP there is no page to serve: a web root given anyway shows a misunderstanding.
  if (o.rfb_only && !o.web_root.empty()) outcome.error = "--rfb-only serves no page; drop --web-root";
  if ((!o.rosbridge_token_file.empty() || !o.rosbridge_ca.empty()) && o.rosbridge_connect.empty()) {
    outcome.error = "--rosbridge-token-file and --rosbridge-ca are for --rosbridge-connect; give it too";
  }
  // Silently ignoring them would leave the caller believing a TCP port is open.
  if (!o.unix_socket.empty() && (app.count("--port") > 0 || app.count("--bind") > 0)) {
    outcome.error = "--unix-socket replaces --port and --bind; drop them";
  }
  return outcome;
}

}  // namespace rfbsim::sim
