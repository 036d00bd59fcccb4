// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "config/config.hpp"
#include "config/settings_table.hpp"
#include "scratch_dir.hpp"

using Catch::Contains;
using rfbsim::manager::ConfigOutcome;
using rfbsim::manager::ManagerConfig;
using rfbsim::manager::parse_manager_args;
using rfbsim::manager::print_config;
using rfbsim::test::ScratchDir;

using Strings = std::vector<std::string>;
using Environment = std::vector<std::pair<std::string, std::string>>;

namespace {

// What `sim_manager ARGS --print-config` prints, with `environment`; fails the test on a parse error.
std::string printed(Strings args, const Environment& environment = {}) {
  args.emplace_back("--print-config");
  const ConfigOutcome outcome = parse_manager_args(args, environment);
  INFO(outcome.error);
  REQUIRE(outcome.error.empty());
  CHECK(outcome.print_config);
  return print_config(outcome.config);
}

// Prints the settings of `args`, reads the print back as the only config file and prints again: the two match.
std::string round_trip(const Strings& args, const Environment& environment = {}) {
  const std::string first = printed(args, environment);
  ScratchDir dir;
  const std::string second = printed({"--config", dir.write("printed.yaml", first)}, environment);
  CHECK(second == first);
  return first;
}

}  // namespace

TEST_CASE("the printed config of the defaults reads back as the defaults") {
  const std::string text = round_trip({});
  CHECK_THAT(text, Contains("\nport: 8080\n"));
  CHECK_THAT(text, Contains("\nscenarios:\n  - warehouse\n  - lab\n"));
  CHECK_THAT(text, Contains("\nframe_origins: []\n"));
  // Unset settings whose defaults depend on others stay unset: a number there would pin them.
  CHECK_THAT(text, Contains("\n# max_duration_s: (unset: 300, or what the tasks need)\n"));
  CHECK_THAT(text, Contains("\n# limit_address_space_mb: (unset: 8192 (x11: 65536))\n"));
  CHECK_THAT(text, Contains("\n# admin_token:\n"));
  CHECK_THAT(text, Contains("\nros:\n  # connect: (unset: none: no ROS)\n"));
  CHECK_THAT(text, Contains("\n  namespace: /rfbsim\n"));
  CHECK_THAT(text, Contains("\nx11:\n  geometry: 1280x720\n  depth: 24\n  xvnc: /usr/bin/Xvnc\n"));
  // Every setting of the table appears, set or as a comment.
  for (const auto& setting : rfbsim::manager::config_table::settings()) {
    const std::string name = rfbsim::manager::config_table::file_name_of(setting.key);
    const std::string last = name.substr(name.find('.') + 1);
    CHECK_THAT(text, Contains(last + ":"));
  }
}

TEST_CASE("the printed config merges the file, the flags and the environment, and reads back the same") {
  ScratchDir dir;
  const std::string file = dir.write("manager.yaml", R"(port: 9090
session_kind: rfb
session_command: /opt/prog
session_args: ["--listen", "127.0.0.1:{port}", "a b", "null", "say \"hi\"", "", "-x", "#1", "tab\there"]
max_duration_s: 600
frame_origins: [https://survey.example.org]
trusted_proxies: [10.0.0.0/8, 127.0.0.1]
limit_cpu_time_factor: 1.5
x11:
  geometry: 640x480
)");
  const std::string text = round_trip({"--config", file, "--max-sessions", "7", "--scenarios", "demo,lab=/srv/lab.yaml",
                                       "--admin-token", "0123456789abcdef"},
                                      {{"RFBSIM_LINK_SECRET", "fedcba9876543210"}});
  CHECK_THAT(text, Contains("\nport: 9090\n"));           // the file
  CHECK_THAT(text, Contains("\nmax_sessions: 7\n"));      // a flag
  CHECK_THAT(text, Contains("\nmax_duration_s: 600\n"));  // set in the file: a number
  CHECK_THAT(text, Contains("\nlimit_cpu_time_factor: 1.5\n"));
  CHECK_THAT(text, Contains("\nscenarios:\n  - demo\n  - lab=/srv/lab.yaml\n"));
  CHECK_THAT(text, Contains("\n  - \"127.0.0.1:{port}\"\n  - \"a b\"\n  - \"null\"\n  - \"say \\\"hi\\\"\"\n  - \"\"\n"));
  CHECK_THAT(text, Contains("\n  - \"tab\\x09here\"\n"));
  // Secrets, from a flag and from the environment, are never printed.
  CHECK_THAT(text, Contains("\nadmin_token: <set>\n"));
  CHECK_THAT(text, Contains("\nlink_secret: <set>\n"));
  CHECK_THAT(text, !Contains("0123456789abcdef") && !Contains("fedcba9876543210"));
  CHECK_THAT(text, Contains("\n  geometry: 640x480\n"));
}

TEST_CASE("a printed config's secret placeholder must be filled before sim_manager serves") {
  ScratchDir dir;
  const std::string file = dir.write("printed.yaml", printed({"--link-secret", "0123456789abcdef"}));
  CHECK_THAT(parse_manager_args({"--config", file}).error,
             Contains("link_secret is <set> (as --print-config writes it): give the secret itself by --link-secret"));
  const ConfigOutcome from_environment =
      parse_manager_args({"--config", file}, {{"RFBSIM_LINK_SECRET", "fedcba9876543210"}});
  CHECK(from_environment.error.empty());
  CHECK(from_environment.config.link_secret == "fedcba9876543210");
  const ConfigOutcome from_flag = parse_manager_args({"--config", file, "--link-secret", "aaaaaaaaaaaaaaaa"});
  CHECK(from_flag.error.empty());
  CHECK(from_flag.config.link_secret == "aaaaaaaaaaaaaaaa");
  CHECK(parse_manager_args({"--config", file}, {{"RFBSIM_LINK_SECRET", "<set>"}}).error ==
        "RFBSIM_LINK_SECRET: must be the secret itself, not <set>");
}

TEST_CASE("the printed config keeps what session_kind and cluster_peers settle") {
  // rfb offers no scenarios unless told: the print leaves them unset, not an empty list it could not read.
  const std::string rfb = round_trip({"--session-kind", "rfb", "--session-arg", "{port}"});
  CHECK_THAT(rfb, Contains("\n# scenarios: (unset: rfb, x11: none)\n"));
  ScratchDir dir;
  const std::string cluster =
      round_trip({"--host-id", "h1", "--cluster-peers", "h1=10.0.0.1:8281,h2=10.0.0.2:8281,h3=h3.lab:8281",
                  "--cluster-secret-file", dir.write("secret", "0123456789abcdef0123"), "--ros-connect",
                  "ws://127.0.0.1:9090", "--ros-robot-control", "external"});
  CHECK_THAT(cluster, Contains("\npath_prefix: /h1\n"));
  CHECK_THAT(cluster, Contains("\ncluster_peers:\n  - h1=10.0.0.1:8281\n  - h2=10.0.0.2:8281\n  - h3=h3.lab:8281\n"));
  CHECK_THAT(cluster, Contains("\n# registry_port: (unset: its cluster_peers entry's)\n"));
  CHECK_THAT(cluster, Contains("\nros:\n  connect: ws://127.0.0.1:9090\n"));
  CHECK_THAT(cluster, Contains("\n  robot_control: external\n"));
}
