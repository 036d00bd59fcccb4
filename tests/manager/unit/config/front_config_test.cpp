// SPDX-License-Identifier: GPL-2.0-or-later
// The settings of a manager behind a balancer: path_prefix, agent_port and agent_bind (config.cpp's table),
// as flags and as keys, with the cluster's default prefix.
#include <catch2/catch.hpp>

#include "config/config.hpp"
#include "scratch_dir.hpp"

using Catch::Contains;
using rfbsim::manager::load_config_file;
using rfbsim::manager::ManagerConfig;
using rfbsim::manager::parse_manager_args;
using rfbsim::test::ScratchDir;

TEST_CASE("path prefix and agent settings are off by default") {
  const ManagerConfig config;
  CHECK(config.path_prefix.empty());
  CHECK(config.agent_port == 0);
  CHECK(config.agent_bind.empty());
}

TEST_CASE("path prefix and agent settings as flags and keys") {
  const auto flags = parse_manager_args({"--path-prefix", "/h2", "--agent-port", "9102", "--agent-bind", "10.0.0.5"});
  REQUIRE(flags.error.empty());
  CHECK(flags.config.path_prefix == "/h2");
  CHECK(flags.config.agent_port == 9102);
  CHECK(flags.config.agent_bind == "10.0.0.5");
  ScratchDir dir;
  const auto file = load_config_file(dir.write("m.yaml", "path_prefix: /study-host-3\nagent_port: 9103\n"), ManagerConfig{});
  REQUIRE(file.error.empty());
  CHECK(file.config.path_prefix == "/study-host-3");
  CHECK(file.config.agent_port == 9103);
}

TEST_CASE("bad path prefixes and agent settings name the flag and what is expected") {
  for (const char* bad : {"h2", "/", "/H2", "/h2/", "/a/b", "/h_2", "/h2?x", "/abcdefghijklmnopqrstuvwxyz0123456"}) {
    const auto outcome = parse_manager_args({"--path-prefix", bad});
    CHECK_THAT(outcome.error, Contains("--path-prefix") && Contains("expected / and 1-32 of a-z, 0-9 and -"));
  }
  CHECK_THAT(parse_manager_args({"--agent-port", "65536"}).error, Contains("--agent-port"));
  CHECK_THAT(parse_manager_args({"--agent-port", "-1"}).error, Contains("--agent-port"));
  CHECK_THAT(parse_manager_args({"--agent-bind", "localhost"}).error, Contains("expected a numeric IPv4 address"));
  ScratchDir dir;
  CHECK_THAT(load_config_file(dir.write("m.yaml", "path_prefix: h2\n"), ManagerConfig{}).error,
             Contains("m.yaml:1: path_prefix: expected /"));
}

TEST_CASE("in a cluster the path prefix defaults to the host id, unless given") {
  ScratchDir dir;
  const std::string secret = dir.write("secret", "0123456789abcdef0123456789abcdef");
  const std::vector<std::string> cluster = {"--cluster-peers", "h1=127.0.0.1:7001,h2=127.0.0.1:7002",
                                            "--cluster-secret-file", secret, "--host-id", "h2"};
  CHECK(parse_manager_args(cluster).config.path_prefix == "/h2");
  auto given = cluster;
  given.insert(given.end(), {"--path-prefix", "/second"});
  CHECK(parse_manager_args(given).config.path_prefix == "/second");
  // A single host keeps no prefix unless told.
  CHECK(parse_manager_args({"--host-id", "h2"}).config.path_prefix.empty());
}
