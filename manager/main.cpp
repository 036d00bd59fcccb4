// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager: one public port, one link per participant, one session process per participant.
//
// Everything runs on one asio I/O thread (the main thread): HTTP and WebSocket through websocketpp, the
// relays, the session processes' readiness pipes, their timers and SIGCHLD. SQLite is written from the
// same thread, so no state is shared between threads.
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "admin/metrics.hpp"
#include "admission/link_signature.hpp"
#include "admission/start_request.hpp"
#include "admission/tokens.hpp"
#include "cluster/agent_check.hpp"
#include "cluster/registry_client.hpp"
#include "cluster/registry_server.hpp"
#include "cluster/uid_registry.hpp"
#include "config/config.hpp"
#include "http/frontend.hpp"
#include "rfbsim/log.hpp"
#include "sessions/session_index.hpp"
#include "sessions/supervisor.hpp"

extern char** environ;

namespace {

using rfbsim::manager::ManagerConfig;

std::vector<std::pair<std::string, std::string>> environment_variables() {
  std::vector<std::pair<std::string, std::string>> out;
  for (char** entry = environ; *entry != nullptr; ++entry) {
    const std::string text(*entry);
    const std::size_t eq = text.find('=');
    if (eq != std::string::npos) out.emplace_back(text.substr(0, eq), text.substr(eq + 1));
  }
  return out;
}

// This machine's name as an identifier (letters, digits, - and _), for the index's host_id column.
std::string default_host_id() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "localhost";
  std::string id;
  for (const char* p = name; *p != '\0' && id.size() < 64; ++p) {
    const char ch = *p;
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_';
    id.push_back(ok ? ch : '-');
  }
  return id;
}

bool is_executable(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec) && ::access(path.c_str(), X_OK) == 0;
}

// "sim_rfb" means the one built beside this binary, else the installed one; anything else is a path.
std::string resolve_program(const std::string& command) {
  if (command == "sim_rfb") {
    for (const char* candidate : {RFBSIM_BUILD_SIM_RFB, RFBSIM_INSTALLED_SIM_RFB}) {
      if (is_executable(candidate)) return candidate;
    }
    throw std::runtime_error(std::string("sim_rfb not found (looked for ") + RFBSIM_BUILD_SIM_RFB + " and " +
                             RFBSIM_INSTALLED_SIM_RFB + "); build it or give --session-command");
  }
  if (!is_executable(command)) {
    throw std::runtime_error("session command '" + command + "' is not an executable file (give a full path)");
  }
  return std::filesystem::absolute(command).string();
}

// session_kind x11: the process started per session is rfbsim_x11_session (the one built beside this binary, else
// the installed one), which starts Xvnc and the configured program; both must be there before any link is served.
std::string resolve_x11_session(ManagerConfig& config) {
  config.session_command = resolve_program(config.session_command);
  if (!is_executable(config.x11.xvnc)) {
    throw std::runtime_error("session_kind x11 needs TigerVNC's Xvnc, not found at " + config.x11.xvnc +
                             " (Debian: apt install tigervnc-standalone-server; or set x11.xvnc)");
  }
  for (const char* candidate : {RFBSIM_BUILD_X11_SESSION, RFBSIM_INSTALLED_X11_SESSION}) {
    if (is_executable(candidate)) return candidate;
  }
  throw std::runtime_error(std::string("rfbsim_x11_session not found (looked for ") + RFBSIM_BUILD_X11_SESSION +
                           " and " + RFBSIM_INSTALLED_X11_SESSION + "); build or install rfbsim");
}

std::string resolve_web_root(const std::string& requested) {
  std::vector<std::string> candidates;
  if (!requested.empty()) {
    candidates.push_back(requested);
  } else {
    candidates = {RFBSIM_BUILD_WEB_ROOT, RFBSIM_INSTALLED_WEB_ROOT};
  }
  for (const std::string& candidate : candidates) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(std::filesystem::path(candidate) / "index.html", ec)) return candidate;
  }
  throw std::runtime_error("no participant page found in " + candidates.front() +
                           (requested.empty() ? std::string(" or ") + RFBSIM_INSTALLED_WEB_ROOT : "") +
                           "; build the web target or give --web-root");
}

// Where sim_rfb looks for a scenario given by name (simulator/CMakeLists.txt): the source tree's, then the
// installed ones. Both come from the build (manager/CMakeLists.txt); without them names are not looked up.
std::vector<std::filesystem::path> scenario_search_dirs() {
#if defined(RFBSIM_SOURCE_SCENARIOS) && defined(RFBSIM_INSTALLED_SCENARIOS)
  return {RFBSIM_SOURCE_SCENARIOS, RFBSIM_INSTALLED_SCENARIOS};
#else
  return {};
#endif
}

// Reads what the offered scenarios' files say (their spawn names for /start, their tasks' limits for
// max_duration) into `config`. Throws std::runtime_error for a file that cannot be read or is malformed:
// every session of it would fail. Warns where a name is not found or an explicit max_duration cuts tasks.
void learn_scenarios(ManagerConfig& config) {
  namespace manager = rfbsim::manager;
  // Every session program runs in its session's folder: a FILE relative to where the manager was started
  // must reach it whole (sim_rfb's --scenario, a legacy program's {scenario}).
  for (std::string& entry : config.scenarios) {
    const std::size_t eq = entry.find('=');
    if (eq != std::string::npos && std::filesystem::path(entry.substr(eq + 1)).is_relative()) {
      entry = entry.substr(0, eq + 1) + std::filesystem::absolute(entry.substr(eq + 1)).string();
    }
  }
  if (config.session_kind != manager::SessionKind::kSimRfb) return;  // a legacy program's scenarios are its own
  std::string error;
  std::vector<std::string> missing;
  config.scenario_facts = manager::load_scenario_facts(config.scenarios, scenario_search_dirs(), error, missing);
  if (!error.empty()) throw std::runtime_error(error);
  for (const std::string& entry : missing) {
    rfbsim::log::warn("manager",
                      "warning: scenario %s: no file found where sim_rfb looks by name; its links' spawn "
                      "names are left to sim_rfb and max_duration_s is not fitted to its task",
                      entry.c_str());
  }
  const std::string warning = manager::fit_max_duration(config);
  if (!warning.empty()) rfbsim::log::warn("manager", "warning: %s", warning.c_str());
}

// How long the I/O thread's index reads wait for another connection's lock.
constexpr int kReaderBusyTimeoutMs = 100;

int run(ManagerConfig config) {
  namespace manager = rfbsim::manager;
  rfbsim::log::set_level(config.log_level);  // checked by the config's reader
  const std::string program = config.session_kind == rfbsim::manager::SessionKind::kX11
                                  ? resolve_x11_session(config)
                                  : resolve_program(config.session_command);
  const std::string web_root = resolve_web_root(config.web_root);
  learn_scenarios(config);
  if (config.host_id.empty()) config.host_id = default_host_id();
  std::filesystem::create_directories(std::filesystem::path(config.data_dir) / "sessions");
  // The I/O thread's connection reads only (the writer thread has its own): it waits at most a moment for a
  // lock, since every relay waits with it; a read that fails is a 503 for one request.
  manager::SessionIndex index((std::filesystem::path(config.data_dir) / "sessions.db").string(), kReaderBusyTimeoutMs);

  // The relays see a vanished browser as an error code, never as a signal.
  std::signal(SIGPIPE, SIG_IGN);
  // Each participant costs a few descriptors (their page's connections, the relay's two sockets): take
  // every descriptor the hard limit allows rather than the customary soft 1024.
  rlimit files{};
  if (::getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
    files.rlim_cur = files.rlim_max;
    ::setrlimit(RLIMIT_NOFILE, &files);
  }
  boost::asio::io_context io;
  manager::Metrics metrics;
  manager::Supervisor supervisor(io, config, program, index, metrics);
  if (const auto recovery = supervisor.recover_interrupted(); !recovery.error.empty() && recovery.found == 0) {
    rfbsim::log::error("manager", "cannot mark the sessions the previous run left as interrupted: %s",
                       recovery.error.c_str());
  } else if (recovery.recorded < recovery.found) {
    rfbsim::log::error("manager",
                       "%d session(s) left by the previous run are interrupted, but the index took only %d of them "
                       "(%s); the rest is written again until it does",
                       recovery.found, recovery.recorded, recovery.error.c_str());
  } else if (recovery.found > 0) {
    rfbsim::log::info("manager", "marked %d session(s) left by the previous run as interrupted", recovery.found);
  }
  // Before the first link: the index says what happened to the previous run's sessions.
  supervisor.flush_index();
  // Several hosts: this host's acceptor of the uid registry, and its proposer, which /start asks before it
  // starts a session of a uid new here (docs/architecture.md, "uid registry").
  std::unique_ptr<manager::RegistryServer> registry_server;
  std::unique_ptr<manager::RegistryClient> registry_client;
  if (!config.cluster_peers.empty()) {
    const std::string secret = manager::read_cluster_secret(config.cluster_secret_file);
    const auto self = std::find_if(config.cluster_peers.begin(), config.cluster_peers.end(),
                                   [&](const manager::ClusterPeer& peer) { return peer.id == config.host_id; });
    const std::string registry_address = config.registry_bind.empty() ? config.listen_address : config.registry_bind;
    // The key binds the peer list too: hosts started on different lists cannot count each other's votes.
    const std::string key = manager::registry_key(secret, config.cluster_peers);
    registry_server = std::make_unique<manager::RegistryServer>(
        io, registry_address, self->port, key, config.host_id, config.cluster_peers,
        (std::filesystem::path(config.data_dir) / "sessions.db").string());
    registry_client =
        std::make_unique<manager::RegistryClient>(io, config.cluster_peers, config.host_id, key, *registry_server);
    rfbsim::log::info("manager", "uid registry on %s:%d, host %s of %zu", registry_address.c_str(),
                      registry_server->port(), config.host_id.c_str(), config.cluster_peers.size());
    if (config.cluster_peers.size() % 2 == 0) {
      rfbsim::log::warn("manager",
                        "warning: %zu cluster peers: a majority is %zu of them, so %zu down stop every new uid, "
                        "as with %zu peers; an odd number is better (docs/architecture.md, \"uid registry\")",
                        config.cluster_peers.size(), config.cluster_peers.size() / 2 + 1,
                        config.cluster_peers.size() / 2, config.cluster_peers.size() - 1);
    }
    // An acceptor that forgot what it promised or accepted can let a second home be decided: a host rebuilt
    // with an empty data folder must join under a new id (docs/architecture.md, "uid registry").
    if (index.registry_table_created()) {
      rfbsim::log::warn(
          "manager",
          "WARNING: this host's uid registry records are new (sessions.db or its uid_acceptors "
          "table was just created). Fine on a cluster's first start. If this host ran before and lost its "
          "sessions.db, stop it: it must rejoin under a new host_id, with every host restarted on the new "
          "cluster_peers list (docs/architecture.md, \"uid registry\")");
    }
  }
  const auto frontend = manager::make_frontend(io, config, supervisor, metrics, web_root, registry_client.get());
  // HAProxy's agent-check: asked on every check, so its line always says the load of that moment. It stays up
  // through a shutdown (saying drain) until the I/O loop stops.
  std::unique_ptr<manager::AgentCheckServer> agent;
  if (config.agent_port > 0) {
    const std::string agent_address = config.agent_bind.empty() ? config.listen_address : config.agent_bind;
    agent = std::make_unique<manager::AgentCheckServer>(io, agent_address, config.agent_port, [&supervisor, &config] {
      const int live = static_cast<int>(supervisor.table().size());
      return manager::AgentLoad{config.max_sessions - live, config.max_sessions, supervisor.draining(),
                                supervisor.shutting_down()};
    });
    rfbsim::log::info("manager", "HAProxy agent-check on %s:%d", agent_address.c_str(), agent->port());
  }
  // Without signed links the uid is the only secret: anyone who learns or guesses one can start (or take
  // over) that participant's session. Fine on loopback; on a public address it should be a choice.
  if (config.link_secret.empty() && config.listen_address.rfind("127.", 0) != 0) {
    rfbsim::log::warn("manager",
                      "warning: links are unsigned and the port listens on %s: anyone who knows a uid can start "
                      "or take over its session; set link_secret (docs/security.md)",
                      config.listen_address.c_str());
  }

  // SIGINT / SIGTERM: stop taking connections, end every session, then leave.
  // The close frames sent to browsers get a moment to leave before the I/O loop stops.
  boost::asio::signal_set stop_signals(io, SIGINT, SIGTERM);
  boost::asio::steady_timer last_words(io);
  stop_signals.async_wait([&](const boost::system::error_code& ec, int signal) {
    if (ec) return;
    rfbsim::log::info("manager", "signal %d: ending %zu session(s)", signal, supervisor.table().size());
    frontend->stop();
    supervisor.shutdown([&] {
      last_words.expires_after(std::chrono::milliseconds(200));
      last_words.async_wait([&io](const boost::system::error_code&) { io.stop(); });
    });
  });

  const std::string host = config.listen_address == "0.0.0.0" ? "127.0.0.1" : config.listen_address;
  const std::string base = std::string(frontend->scheme()) + "://" + host + ":" + std::to_string(frontend->port());
  // A program without scenarios (session kinds rfb and x11 by default) takes links with only a uid.
  std::string example = "uid=demo";
  if (!config.scenarios.empty()) example += "&scenario=" + manager::scenario_names(config.scenarios).front();
  if (!config.link_secret.empty()) example = manager::sign_query(example, config.link_secret);
  rfbsim::log::info("manager", "sessions: %s (%s), at most %d, %lld s each, idle timeout %lld s; data in %s",
                    (config.session_kind == manager::SessionKind::kX11 ? config.session_command : program).c_str(),
                    manager::session_kind_name(config.session_kind), config.max_sessions,
                    static_cast<long long>(config.max_duration.count()),
                    static_cast<long long>(config.idle_timeout.count()), config.data_dir.c_str());
  std::printf("sim_manager ready: %s/\nparticipant link: %s/start?%s\n", base.c_str(), base.c_str(), example.c_str());
  std::fflush(stdout);
  // Handlers catch what they can; anything that still escapes is logged and the loop goes on, since every
  // participant's relay lives on it.
  for (;;) {
    try {
      io.run();
      break;
    } catch (const std::exception& error) {
      rfbsim::log::warn("manager", "error on the I/O loop: %s; carrying on", error.what());
    }
  }
  rfbsim::log::flush_suppressed();  // what the rate limit held back is counted before the last line
  rfbsim::log::info("manager", "stopped");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  namespace manager = rfbsim::manager;
  // Everything the manager creates (the index, session folders, logs) is the study's data: private to its user.
  ::umask(077);
  const std::vector<std::string> args(argv + 1, argv + argc);
  manager::ConfigOutcome parsed = manager::parse_manager_args(args, environment_variables());
  if (parsed.help) {
    std::fputs(manager::manager_usage().c_str(), stdout);
    return 0;
  }
  if (!parsed.error.empty()) {
    std::fprintf(stderr, "sim_manager: %s\n(sim_manager --help lists the options)\n", parsed.error.c_str());
    return 2;
  }
  if (parsed.print_config) {
    std::fputs(manager::print_config(parsed.config).c_str(), stdout);
    return 0;
  }
  if (!parsed.sign_query.empty()) {
    if (parsed.config.link_secret.empty()) {
      std::fprintf(stderr, "sim_manager: --sign needs a link secret (--link-secret, the config or RFBSIM_LINK_SECRET)\n");
      return 2;
    }
    try {
      std::printf("%s\n", manager::sign_query(parsed.sign_query, parsed.config.link_secret).c_str());
      return 0;
    } catch (const std::exception& error) {
      std::fprintf(stderr, "sim_manager: --sign: %s\n", error.what());
      return 2;
    }
  }
  // One address key for the index and every session's events.jsonl: the study's RFBSIM_ADDRESS_KEY, else one
  // drawn now (before any thread) and handed to the sessions through the environment they inherit.
  if (const char* key = std::getenv("RFBSIM_ADDRESS_KEY"); key == nullptr || *key == '\0') {
    ::setenv("RFBSIM_ADDRESS_KEY", (manager::new_session_token() + manager::new_session_token()).c_str(), 1);
  }
  try {
    return run(std::move(parsed.config));
  } catch (const std::exception& error) {
    std::fprintf(stderr, "sim_manager: error: %s\n", error.what());
    return 1;
  }
}
