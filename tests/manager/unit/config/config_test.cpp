// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <filesystem>

#include "config/config.hpp"
#include "scratch_dir.hpp"

using Catch::Contains;
using Catch::StartsWith;
using rfbsim::manager::ConfigOutcome;
using rfbsim::manager::load_config_file;
using rfbsim::manager::manager_usage;
using rfbsim::manager::ManagerConfig;
using rfbsim::manager::parse_manager_args;
using rfbsim::manager::session_kind_name;
using rfbsim::manager::session_limits;
using rfbsim::manager::SessionKind;
using rfbsim::manager::validate_config;
using rfbsim::test::ScratchDir;

using Strings = std::vector<std::string>;
using std::chrono::seconds;

namespace {

// The error of a config file holding `yaml`, or "" when it loads.
std::string file_error(const ScratchDir& dir, const std::string& yaml) {
  return load_config_file(dir.write("manager.yaml", yaml), ManagerConfig{}).error;
}

// The error of a command line, or "".
std::string args_error(const Strings& args) { return parse_manager_args(args).error; }

}  // namespace

TEST_CASE("the defaults") {
  const ManagerConfig c;
  CHECK(c.listen_address == "127.0.0.1");
  CHECK(c.port == 8080);
  CHECK(c.tls_certificate.empty());
  CHECK(c.tls_private_key.empty());
  CHECK(c.session_command == "sim_rfb");
  CHECK(c.session_kind == SessionKind::kSimRfb);
  CHECK(c.session_args.empty());
  CHECK(c.codec == "auto");
  CHECK(c.max_sessions == 4);
  CHECK(c.max_duration == seconds(300));
  CHECK(c.idle_timeout == seconds(60));
  CHECK(c.start_timeout == seconds(30));
  CHECK(c.stop_grace == seconds(5));
  CHECK(c.data_dir == "rfbsim-data");
  CHECK(c.scenarios == Strings{"warehouse", "lab"});
  CHECK(c.frame_origins.empty());
  CHECK(c.admin_token.empty());
  CHECK(c.link_secret.empty());
  CHECK_FALSE(c.allow_repeat);
  CHECK(c.host_id.empty());
  CHECK(c.web_root.empty());
  CHECK(c.public_url.empty());
  CHECK(c.limits.address_space_mb == rfbsim::manager::kDefaultAddressSpaceMb);  // 8192, or 0 under ASan
  CHECK(c.limits.open_files == 1024);
  CHECK(c.limits.cpu_time_factor == 2.0);
  CHECK(c.limits.cpu_slack == seconds(60));
  CHECK(std::string(session_kind_name(SessionKind::kSimRfb)) == "sim_rfb");
  CHECK(std::string(session_kind_name(SessionKind::kRfb)) == "rfb");
  CHECK(std::string(session_kind_name(SessionKind::kX11)) == "x11");
}

TEST_CASE("an empty command line gives the defaults") {
  const ConfigOutcome outcome = parse_manager_args({});
  CHECK(outcome.error.empty());
  CHECK_FALSE(outcome.help);
  CHECK(outcome.sign_query.empty());
  CHECK(outcome.config.port == 8080);
  CHECK(outcome.config.scenarios == Strings{"warehouse", "lab"});
}

TEST_CASE("a config file sets every key") {
  ScratchDir dir;
  const std::string path = dir.write("manager.yaml", R"(# sim_manager
listen_address: 0.0.0.0
port: 9090
tls_certificate: /etc/rfbsim/cert.pem
tls_private_key: /etc/rfbsim/key.pem
session_command: /opt/rfbsim/bin/sim_rfb
session_kind: rfb
session_args: ["--listen", "127.0.0.1:{port}", "--quiet"]
codec: h264
max_sessions: 12
max_duration_s: 600
idle_timeout_s: 90
start_timeout_s: 45
stop_grace_s: 0
data_dir: /var/lib/rfbsim
scenarios: [warehouse, "lab=/srv/lab.yaml"]
frame_origins:
  - https://survey.example.org
  - http://localhost:3000
admin_token: aaaaaaaaaaaaaaaa
link_secret: bbbbbbbbbbbbbbbbbbbb
allow_repeat: yes
host_id: node-1
web_root: /srv/rfbsim/web
public_url: https://h1.study.example.org
limit_address_space_mb: 4096
limit_open_files: 256
limit_cpu_time_factor: 1.5
limit_cpu_slack_s: 30
)");
  const ConfigOutcome outcome = load_config_file(path, ManagerConfig{});
  REQUIRE(outcome.error.empty());
  const ManagerConfig& c = outcome.config;
  CHECK(c.listen_address == "0.0.0.0");
  CHECK(c.port == 9090);
  CHECK(c.tls_certificate == "/etc/rfbsim/cert.pem");
  CHECK(c.tls_private_key == "/etc/rfbsim/key.pem");
  CHECK(c.session_command == "/opt/rfbsim/bin/sim_rfb");
  CHECK(c.session_kind == SessionKind::kRfb);
  CHECK(c.session_args == Strings{"--listen", "127.0.0.1:{port}", "--quiet"});
  CHECK(c.codec == "h264");
  CHECK(c.max_sessions == 12);
  CHECK(c.max_duration == seconds(600));
  CHECK(c.idle_timeout == seconds(90));
  CHECK(c.start_timeout == seconds(45));
  CHECK(c.stop_grace == seconds(0));
  CHECK(c.data_dir == "/var/lib/rfbsim");
  CHECK(c.scenarios == Strings{"warehouse", "lab=/srv/lab.yaml"});
  CHECK(c.frame_origins == Strings{"https://survey.example.org", "http://localhost:3000"});
  CHECK(c.admin_token == "aaaaaaaaaaaaaaaa");
  CHECK(c.link_secret == "bbbbbbbbbbbbbbbbbbbb");
  CHECK(c.allow_repeat);
  CHECK(c.host_id == "node-1");
  CHECK(c.web_root == "/srv/rfbsim/web");
  CHECK(c.public_url == "https://h1.study.example.org");
  CHECK(c.limits.address_space_mb == 4096);
  CHECK(c.limits.open_files == 256);
  CHECK(c.limits.cpu_time_factor == 1.5);
  CHECK(c.limits.cpu_slack == seconds(30));
  CHECK(validate_config(c).empty());
}

TEST_CASE("a config file changes only the keys it names") {
  ScratchDir dir;
  ManagerConfig base;
  base.port = 1234;
  base.data_dir = "/base";
  const ConfigOutcome outcome = load_config_file(dir.write("manager.yaml", "data_dir: /file\n"), base);
  REQUIRE(outcome.error.empty());
  CHECK(outcome.config.port == 1234);
  CHECK(outcome.config.data_dir == "/file");
}

TEST_CASE("an empty config file keeps the defaults") {
  ScratchDir dir;
  const ConfigOutcome outcome = load_config_file(dir.write("manager.yaml", "# nothing yet\n"), ManagerConfig{});
  CHECK(outcome.error.empty());
  CHECK(outcome.config.port == 8080);
}

TEST_CASE("lists in a config file may be comma-separated scalars") {
  ScratchDir dir;
  const ConfigOutcome outcome =
      load_config_file(dir.write("manager.yaml", "scenarios: a,b=/x.yaml\nframe_origins: https://a.example\n"),
                       ManagerConfig{});
  REQUIRE(outcome.error.empty());
  CHECK(outcome.config.scenarios == Strings{"a", "b=/x.yaml"});
  CHECK(outcome.config.frame_origins == Strings{"https://a.example"});
}

TEST_CASE("booleans in a config file") {
  ScratchDir dir;
  for (const char* yes : {"true", "yes", "1"}) {
    CHECK(load_config_file(dir.write("manager.yaml", std::string("allow_repeat: ") + yes), ManagerConfig{})
              .config.allow_repeat);
  }
  ManagerConfig base;
  base.allow_repeat = true;
  for (const char* no : {"false", "no", "0"}) {
    CHECK_FALSE(load_config_file(dir.write("manager.yaml", std::string("allow_repeat: ") + no), base).config.allow_repeat);
  }
  const std::string path = dir.path("manager.yaml");
  CHECK(file_error(dir, "allow_repeat: maybe\n") == path + ":1: allow_repeat: expected true or false");
}

TEST_CASE("an unknown key names the file, the line and the key") {
  ScratchDir dir;
  const std::string path = dir.path("manager.yaml");
  CHECK(file_error(dir, "port: 9090\n\nmax_session: 3\n") == path + ":3: max_session: unknown setting");
}

TEST_CASE("bad values name the file, the line, the key and what is expected") {
  ScratchDir dir;
  const std::string at = dir.path("manager.yaml") + ":2: ";
  const auto error = [&](const std::string& line) { return file_error(dir, "port: 9090\n" + line + "\n"); };
  CHECK(error("port: 70000") == at + "port: expected an integer 0..65535");
  CHECK(error("port: -1") == at + "port: expected an integer 0..65535");
  CHECK(error("port: 80x") == at + "port: expected an integer 0..65535");
  CHECK(error("port: 0x50") == at + "port: expected an integer 0..65535");
  CHECK(error("max_sessions: 0") == at + "max_sessions: expected an integer 1..10000");
  CHECK(error("max_duration_s: 0") == at + "max_duration_s: expected whole seconds 1..604800");
  CHECK(error("idle_timeout_s: 604801") == at + "idle_timeout_s: expected whole seconds 1..604800");
  CHECK(error("stop_grace_s: -1") == at + "stop_grace_s: expected whole seconds 0..604800");
  CHECK(error("listen_address: localhost") == at + "listen_address: expected a numeric IPv4 address");
  CHECK(error("listen_address: \"::1\"") == at + "listen_address: expected a numeric IPv4 address");
  CHECK(error("listen_address: 127.1") == at + "listen_address: expected a numeric IPv4 address");
  CHECK(error("frame_origins: [https://x.example/path]") ==
        at + "frame_origins: 'https://x.example/path' is not an origin such as https://survey.example.org "
             "(lower case, no path)");
  CHECK(error("frame_origins: [\"HTTPS://X\"]") ==
        at + "frame_origins: 'HTTPS://X' is not an origin such as https://survey.example.org (lower case, no path)");
  CHECK_THAT(error("frame_origins: [https://X.example]"), StartsWith(at + "frame_origins: 'https://X.example'"));
  CHECK_THAT(error("frame_origins: [\"https://\"]"), StartsWith(at + "frame_origins: 'https://'"));
  CHECK_THAT(error("frame_origins: [\"*\"]"), StartsWith(at + "frame_origins: '*'"));
  CHECK_THAT(error("frame_origins: [\"https://user@x.example\"]"), StartsWith(at + "frame_origins: 'https://user@x"));
  CHECK(error("admin_token: 0123456789abcde") == at + "admin_token: must be at least 16 characters");
  CHECK(error("link_secret: short") == at + "link_secret: must be at least 16 characters");
  CHECK(error("session_kind: docker") == at + "session_kind: expected sim_rfb, rfb or x11");
  CHECK(error("codec: vp9") == at + "codec: expected auto, jpeg or h264");
  CHECK(error("codec: H264") == at + "codec: expected auto, jpeg or h264");
  CHECK(error("codec: \"\"") == at + "codec: expected auto, jpeg or h264");
  CHECK(error("scenarios: [lab, ../x]") ==
        at + "scenarios: '../x' is not a scenario name (letters, digits, - and _, at most 64), optionally =FILE");
  CHECK(error("scenarios: []") == at + "scenarios: list at least one scenario");
  CHECK(error("public_url: https://h1.example.org/") ==
        at + "public_url: expected an origin such as https://h1.study.example.org (no path)");
  CHECK(error("host_id: node.1") == at + "host_id: expected letters, digits, - and _ (at most 64)");
  CHECK(error("data_dir: \"\"") == at + "data_dir: must not be empty");
  CHECK(error("limit_open_files: many") == at + "limit_open_files: expected a count, 0 = no limit");
  CHECK(error("limit_address_space_mb: -5") == at + "limit_address_space_mb: expected MiB, 0 = no limit");
  CHECK(error("limit_cpu_time_factor: -1") == at + "limit_cpu_time_factor: expected cores per session 0..256, 0 = no CPU limit");
  CHECK(error("limit_cpu_time_factor: nan") == at + "limit_cpu_time_factor: expected cores per session 0..256, 0 = no CPU limit");
  CHECK(error("limit_cpu_slack_s: 86401") == at + "limit_cpu_slack_s: expected whole seconds 0..86400");
}

TEST_CASE("values of the wrong YAML shape are errors") {
  ScratchDir dir;
  const std::string at = dir.path("manager.yaml") + ":1: ";
  CHECK(file_error(dir, "port: [1]\n") == at + "port: expected a single value");
  CHECK(file_error(dir, "port:\n") == at + "port: expected a single value");
  CHECK(file_error(dir, "scenarios: {a: 1}\n") == at + "scenarios: expected a list");
  CHECK(file_error(dir, "scenarios: [[a]]\n") == at + "scenarios: expected a list of plain values");
}

TEST_CASE("a config file that is not a mapping of settings is an error") {
  ScratchDir dir;
  const std::string path = dir.path("manager.yaml");
  CHECK(file_error(dir, "- port\n- 9090\n") == path + ": expected a mapping of settings (key: value)");
  CHECK(file_error(dir, "just text\n") == path + ": expected a mapping of settings (key: value)");
  CHECK_THAT(file_error(dir, "port: 9090\nscenarios: [a,\n"), StartsWith(path + ":"));
}

TEST_CASE("a key that is not a plain name is an error naming the file and line, not an exception") {
  ScratchDir dir;
  const std::string path = dir.path("manager.yaml");
  ConfigOutcome outcome;
  REQUIRE_NOTHROW(outcome = load_config_file(dir.write("manager.yaml", "port: 9090\n[a, b]: 1\n"), ManagerConfig{}));
  CHECK(outcome.error == path + ":2: expected a setting name as key");
  CHECK(file_error(dir, "~: 1\n") == path + ":1: expected a setting name as key");
}

TEST_CASE("a missing config file is an error naming it") {
  ScratchDir dir;
  const std::string path = dir.path("missing.yaml");
  CHECK(load_config_file(path, ManagerConfig{}).error == path + ": cannot read the file");
  CHECK(args_error({"--config", path}) == path + ": cannot read the file");
}

TEST_CASE("flags set the config") {
  const ConfigOutcome outcome = parse_manager_args({"--listen-address", "0.0.0.0", "--port", "0", "--max-sessions",
                                                    "2", "--scenarios", "a,b=/x.yaml", "--frame-origins",
                                                    "https://a.example,https://b.example", "--allow-repeat", "true",
                                                    "--idle-timeout-s", "15", "--limit-cpu-time-factor", "0",
                                                    "--public-url", "http://10.0.0.2:8080"});
  REQUIRE(outcome.error.empty());
  CHECK(outcome.config.listen_address == "0.0.0.0");
  CHECK(outcome.config.port == 0);
  CHECK(outcome.config.max_sessions == 2);
  CHECK(outcome.config.scenarios == Strings{"a", "b=/x.yaml"});
  CHECK(outcome.config.frame_origins == Strings{"https://a.example", "https://b.example"});
  CHECK(outcome.config.allow_repeat);
  CHECK(outcome.config.idle_timeout == seconds(15));
  CHECK(outcome.config.limits.cpu_time_factor == 0.0);
  CHECK(outcome.config.public_url == "http://10.0.0.2:8080");
}

TEST_CASE("the codec is a key and a flag, the flag winning, each value checked") {
  ScratchDir dir;
  const std::string path = dir.write("manager.yaml", "port: 8000\ncodec: jpeg\n");
  CHECK(parse_manager_args({"--config", path}).config.codec == "jpeg");
  CHECK(parse_manager_args({"--config", path, "--codec", "h264"}).config.codec == "h264");
  CHECK(parse_manager_args({"--codec", "auto"}).config.codec == "auto");
  CHECK(args_error({"--codec", "x264"}) == "--codec 'x264': expected auto, jpeg or h264");
  CHECK(args_error({"--codec"}) == "--codec needs a value");
  CHECK_THAT(manager_usage(), Contains("--codec auto|jpeg|h264"));
}

TEST_CASE("flags override the config file wherever --config stands") {
  ScratchDir dir;
  const std::string path = dir.write("manager.yaml", "port: 8000\nmax_sessions: 3\n");
  for (const Strings& args : {Strings{"--port", "9000", "--config", path}, Strings{"--config", path, "--port", "9000"}}) {
    const ConfigOutcome outcome = parse_manager_args(args);
    REQUIRE(outcome.error.empty());
    CHECK(outcome.config.port == 9000);
    CHECK(outcome.config.max_sessions == 3);
  }
}

TEST_CASE("repeated --session-arg flags replace the file's list as a whole") {
  ScratchDir dir;
  const std::string path = dir.write("manager.yaml", "session_args: [--from-file, one]\n");
  SECTION("flags given") {
    const ConfigOutcome outcome =
        parse_manager_args({"--session-arg", "--width", "--config", path, "--session-arg", "640"});
    REQUIRE(outcome.error.empty());
    CHECK(outcome.config.session_args == Strings{"--width", "640"});
  }
  SECTION("no flags: the file's list") {
    const ConfigOutcome outcome = parse_manager_args({"--config", path});
    REQUIRE(outcome.error.empty());
    CHECK(outcome.config.session_args == Strings{"--from-file", "one"});
  }
  SECTION("a value with a comma stays one argument") {
    const ConfigOutcome outcome = parse_manager_args({"--session-arg", "--avatar-start=1,2,0"});
    CHECK(outcome.config.session_args == Strings{"--avatar-start=1,2,0"});
  }
}

TEST_CASE("secrets come from the environment only where flags and file left them empty") {
  ScratchDir dir;
  const std::vector<std::pair<std::string, std::string>> environment = {
      {"RFBSIM_ADMIN_TOKEN", "environment-admin-1"}, {"RFBSIM_LINK_SECRET", "environment-secret-1"},
      {"PATH", "/usr/bin"}};
  SECTION("neither given: both from the environment") {
    const ConfigOutcome outcome = parse_manager_args({}, environment);
    REQUIRE(outcome.error.empty());
    CHECK(outcome.config.admin_token == "environment-admin-1");
    CHECK(outcome.config.link_secret == "environment-secret-1");
  }
  SECTION("a flag wins") {
    const ConfigOutcome outcome = parse_manager_args({"--admin-token", "flag-admin-token-1"}, environment);
    REQUIRE(outcome.error.empty());
    CHECK(outcome.config.admin_token == "flag-admin-token-1");
    CHECK(outcome.config.link_secret == "environment-secret-1");
  }
  SECTION("the file wins") {
    const std::string path = dir.write("manager.yaml", "link_secret: file-link-secret-1\n");
    const ConfigOutcome outcome = parse_manager_args({"--config", path}, environment);
    REQUIRE(outcome.error.empty());
    CHECK(outcome.config.admin_token == "environment-admin-1");
    CHECK(outcome.config.link_secret == "file-link-secret-1");
  }
  SECTION("a short secret in the environment is an error naming the variable") {
    const ConfigOutcome outcome = parse_manager_args({}, {{"RFBSIM_LINK_SECRET", "short"}});
    CHECK(outcome.error == "RFBSIM_LINK_SECRET: must be at least 16 characters");
  }
  SECTION("no environment: no secrets") {
    const ConfigOutcome outcome = parse_manager_args({});
    CHECK(outcome.config.admin_token.empty());
    CHECK(outcome.config.link_secret.empty());
  }
}

TEST_CASE("the --help and --sign flags") {
  CHECK(parse_manager_args({"--help"}).help);
  CHECK(parse_manager_args({"-h"}).help);
  CHECK(parse_manager_args({"--port", "1", "--help"}).help);
  const ConfigOutcome sign = parse_manager_args({"--sign", "uid=p01&scenario=lab", "--link-secret", "0123456789abcdef"});
  CHECK(sign.error.empty());
  CHECK_FALSE(sign.help);
  CHECK(sign.sign_query == "uid=p01&scenario=lab");
  CHECK(sign.config.link_secret == "0123456789abcdef");
  CHECK_THAT(manager_usage(), StartsWith("usage: sim_manager"));
  CHECK_THAT(manager_usage(), Contains("--sign QUERY"));
}

TEST_CASE("bad command lines say what is wrong") {
  CHECK(args_error({"--bogus", "1"}) == "unknown argument '--bogus'");
  CHECK(args_error({"--session-args", "x"}) == "unknown argument '--session-args'");
  CHECK(args_error({"--session_args", "x"}) == "unknown argument '--session_args'");
  CHECK(args_error({"serve"}) == "unknown argument 'serve'");
  CHECK(args_error({"-p", "80"}) == "unknown argument '-p'");
  CHECK(args_error({"--port"}) == "--port needs a value");
  CHECK(args_error({"--config"}) == "--config needs a value");
  CHECK(args_error({"--port", "70000"}) == "--port '70000': expected an integer 0..65535");
  CHECK(args_error({"--max-sessions", "0"}) == "--max-sessions '0': expected an integer 1..10000");
  CHECK(args_error({"--listen-address", "localhost"}) == "--listen-address 'localhost': expected a numeric IPv4 address");
  CHECK(args_error({"--session-kind", "docker"}) == "--session-kind 'docker': expected sim_rfb, rfb or x11");
  CHECK(args_error({"--scenarios", "lab,../x"}) ==
        "--scenarios 'lab,../x': '../x' is not a scenario name (letters, digits, - and _, at most 64), optionally =FILE");
  CHECK(args_error({"--scenarios", ""}) == "--scenarios '': list at least one scenario");
  CHECK(args_error({"--frame-origins", "https://x.example/path"}) ==
        "--frame-origins 'https://x.example/path': 'https://x.example/path' is not an origin such as "
        "https://survey.example.org (lower case, no path)");
}

TEST_CASE("settings that cannot work together") {
  ManagerConfig c;
  CHECK(validate_config(c).empty());
  SECTION("a TLS certificate without a key, or a key without a certificate") {
    c.tls_certificate = "/cert.pem";
    CHECK(validate_config(c) == "TLS needs both tls_certificate and tls_private_key");
    c.tls_certificate.clear();
    c.tls_private_key = "/key.pem";
    CHECK(validate_config(c) == "TLS needs both tls_certificate and tls_private_key");
    c.tls_certificate = "/cert.pem";
    CHECK(validate_config(c).empty());
  }
  SECTION("an rfb program that is not told its port") {
    c.session_kind = SessionKind::kRfb;
    c.session_args = {"--listen", "5900"};
    CHECK(validate_config(c) == "session_kind rfb needs {port} in session_args, where the program is told its port");
    c.session_args = {"--listen=127.0.0.1:{port}"};
    CHECK(validate_config(c).empty());
  }
  SECTION("the command line is validated as a whole") {
    CHECK(args_error({"--tls-certificate", "/cert.pem"}) == "TLS needs both tls_certificate and tls_private_key");
    CHECK(args_error({"--session-kind", "rfb"}) ==
          "session_kind rfb needs {port} in session_args, where the program is told its port");
    CHECK(args_error({"--session-kind", "rfb", "--session-arg", "{port}"}).empty());
  }
}

TEST_CASE("sessions get an 8 GiB address-space limit by default, except in AddressSanitizer builds") {
#if defined(__SANITIZE_ADDRESS__)
  CHECK(rfbsim::manager::kDefaultAddressSpaceMb == 0);
#else
  CHECK(rfbsim::manager::kDefaultAddressSpaceMb == 8192);
#endif
}

TEST_CASE("max_duration fits the offered scenarios' tasks unless the config sets it") {
  using rfbsim::manager::fit_max_duration;
  using rfbsim::manager::ScenarioFacts;
  using rfbsim::manager::session_time_needed;
  ScenarioFacts warehouse;  // SEAN-EP's: a 240 s timer, 15 s to read the code
  warehouse.name = "warehouse";
  warehouse.has_task = true;
  ScenarioFacts long_task = warehouse;
  long_task.name = "long";
  long_task.time_limit_s = 600.5;
  long_task.end_grace_s = 20;
  ScenarioFacts free_walk;  // no task: nothing ends it but the manager
  free_walk.name = "free";

  ManagerConfig c;
  CHECK_FALSE(c.max_duration_set);
  // The clock starts at the latest when the start timeout (30 s) runs out, later than the first browser's
  // 20 s; then 240 s, 15 s of grace and 5 s for sim_rfb to write and leave.
  CHECK(session_time_needed(c, warehouse) == seconds(30 + 240 + 15 + 5));
  CHECK(session_time_needed(c, long_task) == seconds(30 + 601 + 20 + 5));  // rounded up
  CHECK(session_time_needed(c, free_walk) == seconds(0));
  SECTION("the later of the start timeout and the first browser's wait counts") {
    c.first_connect_timeout = seconds(50);
    CHECK(session_time_needed(c, warehouse) == seconds(50 + 260));
    c.idle_timeout = seconds(40);  // the first browser's wait is the idle timeout where that is shorter
    CHECK(session_time_needed(c, warehouse) == seconds(40 + 260));
  }
  SECTION("sim_rfb's --time-limit in session_args wins over the scenario's, the last one given") {
    c.session_args = {"--time-limit", "100", "--fps", "15", "--time-limit", "60"};
    CHECK(session_time_needed(c, warehouse) == seconds(30 + 60 + 15 + 5));
    c.session_args = {"--time-limit", "1.5"};  // sim_rfb refuses it; the scenario's is what is known
    CHECK(session_time_needed(c, warehouse) == seconds(290));
  }
  SECTION("the default fits the shipped scenarios as it is, and grows for a longer task") {
    c.scenario_facts = {warehouse, free_walk};
    CHECK(fit_max_duration(c).empty());
    CHECK(c.max_duration == seconds(300));  // SEAN-EP's 5 min still covers 290 s
    c.scenario_facts = {warehouse, long_task, free_walk};
    CHECK(fit_max_duration(c).empty());
    CHECK(c.max_duration == seconds(656));
  }
  SECTION("a max_duration the config sets is kept, with a warning for each task it can cut short") {
    const ConfigOutcome parsed = parse_manager_args({"--max-duration-s", "280"});
    REQUIRE(parsed.error.empty());
    c = parsed.config;
    CHECK(c.max_duration_set);
    c.scenario_facts = {warehouse, long_task, free_walk};
    CHECK(fit_max_duration(c) ==
          "max_duration_s 280 can end a session of warehouse before its task does (it needs 290 s: the start, a time "
          "limit of 240 s and an end grace of 15 s; docs/deployment.md); max_duration_s 280 can end a session of long "
          "before its task does (it needs 656 s: the start, a time limit of 601 s and an end grace of 20 s; "
          "docs/deployment.md)");
    CHECK(c.max_duration == seconds(280));
    c.max_duration = seconds(700);
    CHECK(fit_max_duration(c).empty());
  }
  SECTION("max_duration_s in a config file counts as set too") {
    ScratchDir dir;
    const ConfigOutcome loaded = load_config_file(dir.write("manager.yaml", "max_duration_s: 300\n"), ManagerConfig{});
    REQUIRE(loaded.error.empty());
    CHECK(loaded.config.max_duration_set);
    CHECK_FALSE(load_config_file(dir.write("other.yaml", "max_sessions: 2\n"), ManagerConfig{}).config.max_duration_set);
  }
}

TEST_CASE("the ros section: a lab's rosbridge, its token and CA files, the namespace and the default control") {
  ScratchDir dir;
  const std::string token = dir.write("rosbridge.token", "lab-token-0123\n");
  const std::string ca = dir.write("lab-ca.pem", "-----BEGIN CERTIFICATE-----\nMIIB\n-----END CERTIFICATE-----\n");
  const ConfigOutcome outcome = load_config_file(dir.write("manager.yaml", "ros:\n"
                                                                           "  connect: wss://ros.lab.example.org:9090/\n"
                                                                           "  token_file: " + token + "\n"
                                                                           "  ca_file: " + ca + "\n"
                                                                           "  namespace: /lab/study_3\n"
                                                                           "  robot_control: external\n"),
                                                 ManagerConfig{});
  REQUIRE(outcome.error.empty());
  CHECK(outcome.config.ros.connect == "wss://ros.lab.example.org:9090/");
  CHECK(outcome.config.ros.token_file == token);
  CHECK(outcome.config.ros.ca_file == ca);
  CHECK(outcome.config.ros.ros_namespace == "/lab/study_3");
  CHECK(outcome.config.ros.robot_control == "external");
  CHECK(validate_config(outcome.config).empty());
  // The defaults: no ROS, /rfbsim, builtin.
  const ManagerConfig defaults;
  CHECK(defaults.ros.connect.empty());
  CHECK(defaults.ros.token_file.empty());
  CHECK(defaults.ros.ca_file.empty());
  CHECK(defaults.ros.ros_namespace == "/rfbsim");
  CHECK(defaults.ros.robot_control.empty());  // the scenario's own robot.control
  // The same from flags, over the file.
  const ConfigOutcome flags = parse_manager_args({"--ros-connect", "ws://127.0.0.1:9090", "--ros-namespace", "/x",
                                                  "--ros-token-file", token, "--ros-robot-control", "external"});
  REQUIRE(flags.error.empty());
  CHECK(flags.config.ros.connect == "ws://127.0.0.1:9090");
  CHECK(flags.config.ros.ros_namespace == "/x");
  CHECK(flags.config.ros.token_file == token);
  CHECK(flags.config.ros.robot_control == "external");
  CHECK_THAT(manager_usage(), Contains("--ros-connect URL"));
}

TEST_CASE("the ros section's files are made absolute: a session runs in its own folder") {
  ScratchDir dir;
  dir.write("t.token", "abc\n");
  const auto before = std::filesystem::current_path();
  std::filesystem::current_path(dir.path());
  const ConfigOutcome outcome = parse_manager_args({"--ros-connect", "ws://localhost:9090", "--ros-token-file", "t.token"});
  std::filesystem::current_path(before);
  REQUIRE(outcome.error.empty());
  CHECK(outcome.config.ros.token_file == dir.path("t.token"));
}

TEST_CASE("a bad ros section says which key and why") {
  ScratchDir dir;
  const std::string token = dir.write("rosbridge.token", "lab-token\n");
  const std::string yaml = dir.path("manager.yaml");
  CHECK(file_error(dir, "ros:\n  connect: http://ros.lab/\n") ==
        yaml + ":2: ros.connect: expected a ws:// or wss:// URL such as wss://ros.lab.example.org:9090/");
  CHECK(file_error(dir, "ros:\n  connect: \"wss://ros lab/\"\n") ==
        yaml + ":2: ros.connect: must not hold spaces or control characters");
  CHECK(file_error(dir, "ros:\n  connect: wss://me:pw@ros.lab/\n") ==
        yaml + ":2: ros.connect: must not hold user info (user@host): put the credential in token_file");
  CHECK(file_error(dir, "ros:\n  connect: wss://ros.lab/\n  namespace: rfbsim\n") ==
        yaml + ":3: ros.namespace: expected a ROS name such as /rfbsim: '/', then segments of letters, digits and "
               "'_' that start with a letter, joined by '/', no '/' at the end");
  CHECK(file_error(dir, "ros:\n  namespace: /rfbsim/\n") ==
        yaml + ":2: ros.namespace: expected a ROS name such as /rfbsim: '/', then segments of letters, digits and "
               "'_' that start with a letter, joined by '/', no '/' at the end");
  CHECK(file_error(dir, "ros:\n  robot_control: planner\n") == yaml + ":2: ros.robot_control: expected builtin or external");
  CHECK(file_error(dir, "ros:\n  token_file: " + dir.path("nope") + "\n") ==
        yaml + ":2: ros.token_file: cannot read " + dir.path("nope"));
  CHECK(file_error(dir, "ros:\n  ca_file: " + token + "\n") ==
        yaml + ":2: ros.ca_file: " + token + " holds no PEM certificate (-----BEGIN CERTIFICATE-----)");
  CHECK(file_error(dir, "ros:\n  port: 9090\n") ==
        yaml + ":2: ros.port: unknown setting (known: connect, token_file, ca_file, namespace, robot_control, "
               "cmd_vel_type)");
  CHECK(file_error(dir, "ros:\n  cmd_vel_type: Twist\n") == yaml + ":2: ros.cmd_vel_type: expected twist or twist_stamped");
  CHECK(file_error(dir, "ros: wss://ros.lab/\n") ==
        yaml + ":1: ros: expected a mapping (connect, token_file, ca_file, namespace, robot_control, cmd_vel_type)");
  CHECK(file_error(dir, "ros:\n  connect: [a, b]\n") == yaml + ":2: ros.connect: expected a single value");
  CHECK(file_error(dir, "ros_connect: wss://ros.lab/\n") ==
        yaml + ":1: ros_connect: unknown setting (write it as connect: under ros:)");
  // A secret's file content never shows; its path does.
  const std::string two_lines = dir.write("two.token", "secret-a\nsecret-b\n");
  CHECK(file_error(dir, "ros:\n  token_file: " + two_lines + "\n").find("secret-") == std::string::npos);
  CHECK(args_error({"--ros-robot-control", "maybe"}) == "--ros-robot-control 'maybe': expected builtin or external");
  CHECK(args_error({"--ros-port", "9090"}) == "unknown argument '--ros-port'");
}

TEST_CASE("ros settings that cannot work together") {
  ScratchDir dir;
  const std::string token = dir.write("rosbridge.token", "lab-token\n");
  ManagerConfig c;
  c.ros.robot_control = "external";
  CHECK(validate_config(c) == "ros: robot_control external needs connect (the lab's rosbridge)");
  c.ros.robot_control = "builtin";
  c.ros.token_file = token;
  CHECK(validate_config(c) == "ros: token_file and ca_file need connect");
  // A Bearer token over plain ws:// crosses the network in clear, except on loopback.
  c.ros.connect = "ws://ros.lab.example.org:9090/";
  CHECK(validate_config(c) ==
        "ros: token_file needs a wss:// connect: over ws:// the token would cross the network in clear");
  for (const char* loopback : {"ws://127.0.0.1:9090", "ws://localhost/", "ws://[::1]:9090"}) {
    c.ros.connect = loopback;
    CHECK(validate_config(c).empty());
  }
  c.ros.token_file.clear();
  c.ros.ca_file = "/etc/ca.pem";
  CHECK(validate_config(c) == "ros: ca_file needs a wss:// connect");
  c.ros.connect = "wss://ros.lab.example.org/";
  CHECK(validate_config(c).empty());
  c.session_kind = SessionKind::kRfb;
  c.session_args = {"{port}"};
  CHECK(validate_config(c) ==
        "ros: needs session_kind sim_rfb (a legacy program's template may use {robot_control} itself)");
}

TEST_CASE("session_kind x11: the x11 section, its flags, and a program without scenarios") {
  ScratchDir dir;
  const std::string path = dir.write("x11.yaml", R"(session_kind: x11
session_command: /usr/bin/glxgears
session_args: [-geometry, 640x480+0+0]
x11:
  geometry: 640x480
  depth: 16
  xvnc: /opt/tigervnc/bin/Xvnc
)");
  ConfigOutcome outcome = parse_manager_args({"--config", path, "--x11-depth", "24"});
  REQUIRE(outcome.error.empty());
  const ManagerConfig& c = outcome.config;
  CHECK(c.session_kind == SessionKind::kX11);
  CHECK(c.x11.width == 640);
  CHECK(c.x11.height == 480);
  CHECK(c.x11.depth == 24);  // the flag wins over the file
  CHECK(c.x11.xvnc == "/opt/tigervnc/bin/Xvnc");
  // Its links need only uid: no scenarios unless the config names some.
  CHECK(c.scenarios.empty());
  CHECK(parse_manager_args({"--config", path, "--scenarios", "a,b"}).config.scenarios == Strings{"a", "b"});
  // The defaults: the size of sim_rfb's picture, 24 bits, Debian's Xvnc.
  const ManagerConfig defaults;
  CHECK(defaults.x11.width == 1280);
  CHECK(defaults.x11.height == 720);
  CHECK(defaults.x11.depth == 24);
  CHECK(defaults.x11.xvnc == "/usr/bin/Xvnc");
  // An rfb program (a simulator linking librfbsim) has none either; sim_rfb keeps its two.
  CHECK(parse_manager_args({"--session-kind", "rfb", "--session-arg", "{port}"}).config.scenarios.empty());
  CHECK(parse_manager_args({}).config.scenarios == Strings{"warehouse", "lab"});
}

TEST_CASE("a bad x11 section or x11 setting says which key and why") {
  ScratchDir dir;
  const auto error = [&dir](const std::string& text) {
    return load_config_file(dir.write("bad.yaml", text), ManagerConfig{}).error;
  };
  const std::string at = (dir.path() / "bad.yaml").string() + ":";
  CHECK(error("x11:\n  geometry: 640\n") ==
        at + "2: x11.geometry: expected WIDTHxHEIGHT, each 64..8192 (e.g. 1280x720)");
  CHECK(error("x11:\n  geometry: 99999x480\n") ==
        at + "2: x11.geometry: expected WIDTHxHEIGHT, each 64..8192 (e.g. 1280x720)");
  CHECK(error("x11:\n  depth: 8\n") == at + "2: x11.depth: expected 16 or 24");
  CHECK(error("x11:\n  depth: 32\n") == at + "2: x11.depth: expected 16 or 24");
  CHECK(error("x11:\n  xvnc: Xvnc\n") == at + "2: x11.xvnc: expected the absolute path of TigerVNC's Xvnc");
  CHECK(error("x11:\n  display: 3\n") == at + "2: x11.display: unknown setting (known: geometry, depth, xvnc)");
  CHECK(error("x11: 3\n") == at + "1: x11: expected a mapping (geometry, depth, xvnc)");
  CHECK(error("x11_depth: 24\n") == at + "1: x11_depth: unknown setting (write it as depth: under x11:)");
  // The program and its template.
  CHECK(args_error({"--session-kind", "x11"}) ==
        "session_kind x11 needs session_command: the X11 program each session runs (e.g. /usr/bin/glxgears)");
  CHECK(args_error({"--session-kind", "x11", "--session-command", "/usr/bin/xeyes", "--session-arg", "{port}"}) ==
        "session_kind x11 has no {port}: the program draws on its own display, which the manager serves");
  CHECK(args_error({"--session-kind", "x11", "--session-command", "/usr/bin/xeyes"}).empty());
}

TEST_CASE("resource limits per session kind: an x11 program gets more address space unless the config says") {
  ManagerConfig c;
  CHECK(session_limits(c).address_space_mb == rfbsim::manager::kDefaultAddressSpaceMb);
  c.session_kind = SessionKind::kX11;
  CHECK(session_limits(c).address_space_mb == rfbsim::manager::kDefaultX11AddressSpaceMb);
  CHECK(session_limits(c).open_files == c.limits.open_files);
  const ConfigOutcome set = parse_manager_args({"--session-kind", "x11", "--session-command", "/usr/bin/xeyes",
                                                "--limit-address-space-mb", "2048"});
  REQUIRE(set.error.empty());
  CHECK(session_limits(set.config).address_space_mb == 2048);
#if !defined(__SANITIZE_ADDRESS__)
  CHECK(rfbsim::manager::kDefaultX11AddressSpaceMb > rfbsim::manager::kDefaultAddressSpaceMb);
#endif
}
