// SPDX-License-Identifier: GPL-2.0-or-later
// The validators sim_manager and sim_rfb share: exact edges of each rule, and the ROS limits' relation.
#include <catch2/catch.hpp>

#include "contract/validators.hpp"

namespace contract = rfbsim::contract;

TEST_CASE("identifiers are 1 to 64 letters, digits, minus and underscore") {
  CHECK(contract::is_identifier("Az09-_"));
  CHECK(contract::is_identifier(std::string(contract::kMaxIdentifier, 'z')));
  CHECK_FALSE(contract::is_identifier(""));
  CHECK_FALSE(contract::is_identifier(std::string(contract::kMaxIdentifier + 1, 'z')));
  CHECK_FALSE(contract::is_identifier("a.b"));
  CHECK_FALSE(contract::is_identifier("a b"));
}

TEST_CASE("a ROS name has segments that start with a letter, within the limit asked for") {
  CHECK(contract::is_ros_name("/rfbsim/s_12"));
  CHECK(contract::is_ros_name("/a"));
  for (const char* bad : {"", "/", "rfbsim", "/rfbsim/", "//a", "/a//b", "/1a", "/_a", "/a-b", "/a/ b"}) {
    CHECK_FALSE(contract::is_ros_name(bad));
  }
  const std::string longest = "/" + std::string(contract::kMaxRosName - 1, 'a');
  CHECK(contract::is_ros_name(longest));
  CHECK_FALSE(contract::is_ros_name(longest + "a"));
  CHECK_FALSE(contract::is_ros_name(longest, contract::kMaxRosRootName));
}

TEST_CASE("the manager's longest root with the longest session name still passes sim_rfb's check") {
  const std::string root = "/" + std::string(contract::kMaxRosRootName - 1, 'r');
  REQUIRE(contract::is_ros_name(root, contract::kMaxRosRootName));
  const std::string session = root + "/s_18446744073709551615_" + std::string(contract::kMaxIdentifier, 'h');
  CHECK(contract::is_ros_name(session));
}

TEST_CASE("a rosbridge URL is ws or wss with a host and no credential") {
  CHECK(contract::websocket_url_problem("ws://127.0.0.1:9090") == "");
  CHECK(contract::websocket_url_problem("wss://ros.lab.example.org:9090/bridge") == "");
  CHECK(contract::websocket_url_problem("http://ros") != "");
  CHECK(contract::websocket_url_problem("ws://") == "has no host");
  CHECK(contract::websocket_url_problem("ws://:9090") == "has no host");
  CHECK(contract::websocket_url_problem("ws://u:p@ros") != "");
  CHECK(contract::websocket_url_problem("ws://ros/?token=x") != "");
  CHECK(contract::websocket_url_problem("ws://ros/#x") != "");
  CHECK(contract::websocket_url_problem("ws://ro s") != "");
  CHECK(contract::websocket_url_problem("ws://r\xc3\xb6s") != "");
  CHECK(contract::websocket_url_problem("ws://" + std::string(contract::kMaxWebSocketUrl - 5, 'a')) == "");
  CHECK(contract::websocket_url_problem("ws://" + std::string(contract::kMaxWebSocketUrl - 4, 'a')) != "");
}

TEST_CASE("origins: sim_rfb's shape, and the manager's exact browser form within it") {
  for (const char* shape : {"*", "http://a", "https://Study.Example.org:8443", "https://[::1]:8"}) {
    CHECK(contract::looks_like_origin(shape));
  }
  for (const char* bad : {"", "study.example.org", "http://", "https://a/", "https://a?b", "https://u@a", "ftp://a"}) {
    CHECK_FALSE(contract::looks_like_origin(bad));
    CHECK_FALSE(contract::is_browser_origin(bad));
  }
  CHECK(contract::is_browser_origin("https://h1.study.example.org:8443"));
  CHECK(contract::is_browser_origin("http://[::1]:8080"));
  CHECK_FALSE(contract::is_browser_origin("*"));
  CHECK_FALSE(contract::is_browser_origin("https://Study.example.org"));
  CHECK_FALSE(contract::is_browser_origin("https://a_b"));
}
