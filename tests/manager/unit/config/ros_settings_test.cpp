// SPDX-License-Identifier: GPL-2.0-or-later
// The ros section's checks and sessions' ROS names: URLs, ROS names, token and CA files (real files in a scratch
// folder), each with its exact message.
#include <catch2/catch.hpp>

#include <string>

#include "config/ros_settings.hpp"
#include "scratch_dir.hpp"

using rfbsim::manager::ca_file_problem;
using rfbsim::manager::is_ros_name;
using rfbsim::manager::ros_session_name;
using rfbsim::manager::rosbridge_url_problem;
using rfbsim::manager::token_file_problem;
using rfbsim::test::ScratchDir;

TEST_CASE("a ROS name is '/' and segments of letters, digits and '_' that start with a letter") {
  for (const char* name : {"/rfbsim", "/rfbsim/s_12", "/lab/Study_3/x1", "/a"}) {
    INFO(name);
    CHECK(is_ros_name(name));
  }
  for (const char* name : {"", "/", "rfbsim", "/rfbsim/", "//rfbsim", "/rfbsim//s", "/1lab", "/_lab", "/lab/9",
                           "/la-b", "/la b", "/lab.x", "/lab~", "/lab\n", "~/lab"}) {
    INFO(name);
    CHECK_FALSE(is_ros_name(name));
  }
  CHECK(is_ros_name("/" + std::string(199, 'a')));
  CHECK_FALSE(is_ros_name("/" + std::string(200, 'a')));
}

TEST_CASE("the lab's rosbridge is a ws:// or wss:// URL without spaces or user info") {
  for (const char* url : {"wss://ros.lab.example.org:9090/", "ws://127.0.0.1:9090", "wss://[::1]:9090/ros",
                          "ws://ros"}) {
    INFO(url);
    CHECK(rosbridge_url_problem(url).empty());
  }
  CHECK(rosbridge_url_problem("http://ros.lab:9090/") ==
        "expected a ws:// or wss:// URL such as wss://ros.lab.example.org:9090/");
  CHECK(rosbridge_url_problem("WSS://ros.lab/") ==
        "expected a ws:// or wss:// URL such as wss://ros.lab.example.org:9090/");
  CHECK(rosbridge_url_problem("wss://ros lab/") == "must not hold spaces or control characters");
  CHECK(rosbridge_url_problem("wss://ros.lab/\r\nX: y") == "must not hold spaces or control characters");
  CHECK(rosbridge_url_problem(std::string("wss://ros.lab/\0", 15)) == "must not hold spaces or control characters");
  CHECK(rosbridge_url_problem("wss://") == "has no host");
  CHECK(rosbridge_url_problem("wss://:9090/") == "has no host");
  CHECK(rosbridge_url_problem("wss:///path") == "has no host");
  CHECK(rosbridge_url_problem("wss://ros.lab/?token=x") == "must not hold a query or fragment: put a credential in token_file");
  CHECK(rosbridge_url_problem("wss://ros.lab/#x") == "must not hold a query or fragment: put a credential in token_file");
  CHECK(rosbridge_url_problem("wss://user:pw@ros.lab/") ==
        "must not hold user info (user@host): put the credential in token_file");
  // An '@' after the host is a path's, not user info.
  CHECK(rosbridge_url_problem("wss://ros.lab/a@b").empty());
  CHECK(rosbridge_url_problem("wss://ros.lab/" + std::string(2048, 'a')) == "is longer than 2048 characters");
}

TEST_CASE("a token file holds one line of visible ASCII, and the message never shows the token") {
  ScratchDir dir;
  CHECK(token_file_problem(dir.write("good", "s3cr3t-T0ken.value\n")).empty());
  CHECK(token_file_problem(dir.write("crlf", "s3cr3t\r\n")).empty());
  CHECK(token_file_problem(dir.write("bare", "s3cr3t")).empty());
  CHECK(token_file_problem(dir.write("long_ok", std::string(4096, 'k'))).empty());
  const std::string empty = dir.write("empty", "\n");
  CHECK(token_file_problem(empty) == empty + " is empty");
  const std::string two = dir.write("two", "secret-one\nsecret-two\n");
  const std::string why = "must hold one token of visible ASCII (no spaces, lines or control characters)";
  CHECK(token_file_problem(two) == two + " " + why);
  const std::string spaced = dir.write("spaced", "Bearer secret\n");
  CHECK(token_file_problem(spaced) == spaced + " " + why);
  const std::string big = dir.write("big", std::string(5000, 'k'));
  CHECK(token_file_problem(big) == big + " holds more than 4096 characters");
  CHECK(token_file_problem(dir.path("missing")) == "cannot read " + dir.path("missing"));
  CHECK(token_file_problem(dir.path().string()) == "cannot read " + dir.path().string());  // a folder
  CHECK(token_file_problem(two).find("secret") == std::string::npos);
}

TEST_CASE("a CA file holds a PEM certificate") {
  ScratchDir dir;
  CHECK(ca_file_problem(dir.write("ca.pem", "-----BEGIN CERTIFICATE-----\nMIIB\n-----END CERTIFICATE-----\n")).empty());
  const std::string key = dir.write("key.pem", "-----BEGIN PRIVATE KEY-----\nMIIE\n-----END PRIVATE KEY-----\n");
  CHECK(ca_file_problem(key) == key + " holds no PEM certificate (-----BEGIN CERTIFICATE-----)");
  CHECK(ca_file_problem(dir.path("missing.pem")) == "cannot read " + dir.path("missing.pem"));
}

TEST_CASE("a session's ROS name is s_<id>, with the cluster host's id where there are several hosts") {
  CHECK(ros_session_name(12, "") == "s_12");
  CHECK(ros_session_name(1, "h2") == "s_1_h2");
  CHECK(ros_session_name(40, "eu-west-1") == "s_40_eu_west_1");
  CHECK(is_ros_name("/rfbsim/" + ros_session_name(9223372036854775807LL, "0-a")));
}
