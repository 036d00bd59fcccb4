// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's settings: defaults, the YAML config file and the command line, validated without side
// effects so that they can be unit-tested.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "config/ros_settings.hpp"
#include "admission/start_request.hpp"

namespace rfbsim::manager {

/// session_kind x11: the private display each session's program runs on (the `x11:` section).
struct X11Settings {
  int width = 1280;                    ///< the display's and so the picture's size (geometry: WxH)
  int height = 720;
  int depth = 24;                      ///< 16 or 24 bits per pixel
  std::string xvnc = "/usr/bin/Xvnc";  ///< TigerVNC's X server (Debian: tigervnc-standalone-server)
};

/// How the manager talks to the program it starts for each session.
enum class SessionKind {
  kSimRfb,  ///< sim_rfb: the manager adds --port 0 --rfb-only --ready-fd 3, --codec and the link's parameters
  kRfb,     ///< any program serving raw RFB on a loopback port: args may use {port} {scenario} {seed} {uid}
            ///< {data_dir} {t1} {t2} and the overrides' {avatar_start} {avatar_goal} {robot_start}
            ///< {robot_goal} {crowd} {robot_control} (session_arguments); ready once the port accepts a connection.
            ///< A program linking librfbsim (examples/mujoco_rfb) is served this way.
  kX11,     ///< any unmodified X11 program (session_command), per session on its own TigerVNC Xvnc display that
            ///< only the manager reaches (rfbsim_x11_session: an RFB unix socket of mode 0600 and a fresh
            ///< Xauthority); args may use the kRfb placeholders but {port}
};

/// The default RLIMIT_AS of sessions, MiB. AddressSanitizer builds (scripts/test.sh --sanitize) reserve
/// terabytes of shadow address space, which any limit would refuse, so there it is off.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr std::uint64_t kDefaultAddressSpaceMb = 0;
#else
inline constexpr std::uint64_t kDefaultAddressSpaceMb = 8192;
#endif

/// The default RLIMIT_AS of x11 sessions, MiB: a Unity or Gazebo client reserves far more address space than it
/// uses (Unity's Mono heap and Mesa's llvmpipe each map GiBs up front), so sim_rfb's default would refuse them.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr std::uint64_t kDefaultX11AddressSpaceMb = 0;
#else
inline constexpr std::uint64_t kDefaultX11AddressSpaceMb = 65536;
#endif

/// Resource limits applied to every session process (0 = no limit). The defaults depend on the session kind
/// (session_limits) where the config does not set them.
struct ProcessLimits {
  std::uint64_t address_space_mb = kDefaultAddressSpaceMb;  ///< RLIMIT_AS, MiB (llvmpipe reserves a lot)
  bool address_space_set = false;         ///< limit_address_space_mb was given: kept for every kind
  std::uint64_t open_files = 1024;        ///< RLIMIT_NOFILE
  /// RLIMIT_CPU = max_duration x cpu_time_factor + cpu_slack: a session may use about this many cores on
  /// average (renderer threads) and the slack covers start-up and the stop grace period.
  double cpu_time_factor = 2.0;
  std::chrono::seconds cpu_slack{60};
};

/// Limits against abuse of the public port. They apply to every client address, loopback included; a lab
/// whose participants share one address (one NAT) raises them. 0 switches a limit off.
struct AbuseLimits {
  int start_per_minute = 20;       ///< /start requests per address per minute, sustained
  int start_burst = 10;            ///< /start requests per address at once
  int upgrade_per_minute = 60;     ///< WebSocket upgrades per address per minute, sustained (reconnects)
  int upgrade_burst = 30;          ///< WebSocket upgrades per address at once
  int connections_per_address = 64;   ///< open connections per address
  int connections_total = 0;          ///< open connections in all; 0 = from the descriptor limit (see frontend)
  int unspent_sessions_per_address = 3;  ///< live sessions started from one address whose link is not yet spent
  std::chrono::seconds ws_ping_interval{20};  ///< a ping to every WebSocket this often
  std::chrono::seconds ws_pong_timeout{20};   ///< a WebSocket whose pong is this late is closed
};

/// What happens when a session's data can no longer be written (a full disk): the program reports it.
enum class DataFailurePolicy {
  kContinue,  ///< the participant carries on; the session is marked data_incomplete in the index
  kEnd,       ///< the session ends (the page says so and offers the way back to the survey)
};

/// One host of a cluster as cluster_peers names it ("ID=ADDRESS:PORT"): its host id and its uid registry's
/// address and port.
struct ClusterPeer {
  std::string id;       ///< the host's host_id: 1..32 of [a-z0-9-]
  std::string address;  ///< a numeric IPv4 address or a host name
  int port = 0;         ///< its registry port, 1..65535
};

/// Everything sim_manager can be configured with; start from the defaults.
struct ManagerConfig {
  std::string listen_address = "127.0.0.1";  ///< numeric IPv4 address; loopback unless told otherwise
  int port = 8080;                           ///< the one public port (HTTP/WS, or HTTPS/WSS with TLS)
  std::string tls_certificate;               ///< PEM certificate chain; with tls_private_key enables TLS
  std::string tls_private_key;               ///< PEM private key
  std::string session_command = "sim_rfb";   ///< program path; "sim_rfb" = the one built or installed
  SessionKind session_kind = SessionKind::kSimRfb;
  std::vector<std::string> session_args;     ///< extra arguments (kRfb: the whole argument template)
  /// kSimRfb: the picture encoding sim_rfb is started with (--codec): "auto" (Tight JPEG, H.264 for a browser
  /// that offers it once its link needs it), "jpeg" or "h264".
  std::string codec = "auto";
  /// kSimRfb: how the relay reaches a session: "unix" (a socket of mode 0600 in a private folder: only the
  /// manager's user can connect) or "tcp" (a loopback port, which any local user could open; for tools that
  /// connect to sessions directly, such as bench_manager's direct path).
  std::string session_socket = "unix";
  /// The manager's log: error, warn, info (the default) or debug (rfbsim/log.hpp).
  std::string log_level = "info";
  int max_sessions = 4;                      ///< live sessions at once; the next participant is told to wait
  /// A session is ended this long after /start (SEAN-EP: 5 min). Unless set, fit_max_duration raises it to
  /// what the offered scenarios' tasks need.
  std::chrono::seconds max_duration{300};
  bool max_duration_set = false;             ///< max_duration_s was given (file or flag): kept as it is
  std::chrono::seconds idle_timeout{60};     ///< ended after this long with no browser connected
  /// A session no browser ever connected to ends this long after /start (if shorter than idle_timeout): a
  /// participant's page opens its socket within seconds, a link preview never does, and each such session
  /// would hold a slot.
  std::chrono::seconds first_connect_timeout{20};
  std::chrono::seconds start_timeout{30};    ///< a session not ready by then failed to start
  std::chrono::seconds stop_grace{5};        ///< SIGTERM, then SIGKILL after this long
  std::string data_dir = "rfbsim-data";      ///< session index (sessions.db) and one folder per session
  std::vector<std::string> scenarios = {"warehouse", "lab"};  ///< allowed; the first is the default
  /// scenarios was given (file or flag). Unset, kRfb and kX11 sessions have none (finish_config): their links
  /// need only uid, and a program has no scenario unless the config names some for its {scenario}.
  bool scenarios_set = false;
  std::vector<std::string> frame_origins;    ///< origins allowed to frame the page and open its WebSocket
  std::string admin_token;                   ///< empty = /admin and /api are off
  std::string link_secret;                   ///< non-empty = /start links must carry a valid sig
  bool require_link_expiry = false;          ///< with a link secret: links must carry exp (a Unix time, seconds)
  bool allow_repeat = false;                 ///< a uid whose session ended may start another
  bool allow_camera_param = true;            ///< links may choose the view (camera=third_person|first_person)
  /// The video condition (issue 33, sessions/yoking.hpp): how many watchers one interactive session may have,
  /// and how a watcher's source is chosen: "earliest_ended" (each link: the earliest-ended source session of its
  /// scenario with room) or "by_participant" (all of a watcher's links: the same walker's sessions).
  int yoke_max_viewers = 1;
  std::string yoke_policy = "earliest_ended";
  std::string host_id;                       ///< recorded in the index; empty = this machine's host name
  std::string web_root;                      ///< participant page; empty = the built or installed one
  /// This host's own public origin (e.g. https://h2.study.example.org); when set, /start redirects there,
  /// so that a load balancer can hand new links to any host and the session stays with its host.
  std::string public_url;
  /// This manager's part of a balancer's URL space, "/" and 1-32 of [a-z0-9-] (e.g. "/h2"; "" = none): its
  /// pages, status, sockets and admin API answer under it as well as without it, and /start redirects into it.
  /// With cluster_peers and no path_prefix it is "/" + host_id.
  std::string path_prefix;
  /// HAProxy's agent-check port (0 = off): each connection reads "up ready NN%" or "drain" (agent_check.hpp).
  int agent_port = 0;
  std::string agent_bind;  ///< the agent port's numeric IPv4 address; empty = listen_address
  ProcessLimits limits;
  AbuseLimits abuse;
  /// Front ends (nginx, HAProxy) whose X-Forwarded-For names the participant: addresses or CIDR ranges.
  std::vector<std::string> trusted_proxies;
  DataFailurePolicy on_data_incomplete = DataFailurePolicy::kContinue;
  /// Run once a session's folder is final (its process gone, manager.json written) to copy it off this host: an
  /// argument list, never a shell, with {folder} {folder_name} {uid} {host} {session_id} replaced (copy_command.hpp);
  /// empty = no copy. E.g. [rsync, -a, "{folder}/", "store:/study/{host}/{folder_name}/"].
  std::vector<std::string> after_session_command;
  int after_session_retries = 5;  ///< tries after a failed first one (backoff 5 s, doubling up to 5 min)
  std::chrono::seconds after_session_timeout{600};  ///< one try's limit; then SIGTERM, SIGKILL after stop_grace
  /// What the offered scenarios' files say (load_scenario_facts, at start-up; kSimRfb only): spawn names for
  /// /start's checks and task limits for max_duration. Not a setting; empty = nothing known.
  std::vector<ScenarioFacts> scenario_facts;
  /// Every host of the cluster, this one included (empty: a single host). With peers, a uid's home is
  /// decided by the uid registry before a session starts (docs/architecture.md, "uid registry").
  std::vector<ClusterPeer> cluster_peers;
  std::string cluster_secret_file;  ///< the hosts' shared registry secret (>= 16 bytes); needed with peers
  int registry_port = 0;            ///< this host's registry port; 0 = its own cluster_peers entry's
  std::string registry_bind;        ///< the registry's numeric IPv4 address; empty = listen_address
  /// The `ros:` section: sessions of scenarios with a robot dial out to a lab's rosbridge_server (kSimRfb only).
  RosSettings ros;
  X11Settings x11;  ///< the `x11:` section (kX11 only)
};

/// The outcome of reading settings: a config, or a message naming the file, line or flag at fault.
struct ConfigOutcome {
  ManagerConfig config;
  std::string error;  ///< empty on success
  bool help = false;  ///< --help was given
  std::string sign_query;  ///< --sign QUERY was given: print the signed query and exit
  bool print_config = false;  ///< --print-config was given: print the settings as a config file and exit
};

/// Reads a YAML config file over `base`. Unknown keys and bad values are errors naming the key and line.
ConfigOutcome load_config_file(const std::string& path, ManagerConfig base);

/// Parses the command line (without the program name): --config FILE first, then flags over it, then
/// RFBSIM_ADMIN_TOKEN and RFBSIM_LINK_SECRET from `environment` where the flags left them empty (or as the
/// placeholder --print-config writes; that placeholder is refused unless --print-config is given).
ConfigOutcome parse_manager_args(const std::vector<std::string>& args,
                                 const std::vector<std::pair<std::string, std::string>>& environment = {});

/// Settles what depends on the session kind once every source is read: kRfb and kX11 without scenarios_set
/// offer none (links need only uid). parse_manager_args calls it last.
void finish_config(ManagerConfig& config);

/// The resource limits of `config`'s sessions: config.limits, with the address space of its kind's default
/// (kDefaultX11AddressSpaceMb for kX11) unless limit_address_space_mb was set.
ProcessLimits session_limits(const ManagerConfig& config);

/// Checks a finished config for settings that cannot work together; "" when it is fine.
std::string validate_config(const ManagerConfig& config);

/// The margin after a task's end grace for sim_rfb to write the session's last data and exit by itself.
inline constexpr std::chrono::seconds kSessionEndMargin{5};

/// How long after /start a session of `facts` may need, whole seconds rounded up: its task's clock starts when
/// the participant's browser is first served, at the latest when start_timeout or the first-connect timeout
/// (the idle timeout where that is shorter) runs out, whichever is later; then the time limit (sim_rfb's
/// --time-limit in session_args if there, else the scenario's), the end grace and kSessionEndMargin. 0 for a
/// scenario without a task, which never ends by itself.
std::chrono::seconds session_time_needed(const ManagerConfig& config, const ScenarioFacts& facts);

/// Fits max_duration to config.scenario_facts. Unset (the default), it becomes the longest need if that is
/// longer than the default, so that no task is cut short; set, it is kept, and the return value warns, naming
/// each scenario whose task it can cut short and the seconds that one needs ("" when none).
std::string fit_max_duration(ManagerConfig& config);

/// The --help text, from the settings table.
std::string manager_usage();

/// The settings of `config` as a YAML config file, in the table's order: each setting that is set, and each unset
/// one as a comment; secrets as <set>. Read back (with the same environment), it prints the same text.
std::string print_config(const ManagerConfig& config);

/// "sim_rfb", "rfb" or "x11".
const char* session_kind_name(SessionKind kind);

}  // namespace rfbsim::manager
