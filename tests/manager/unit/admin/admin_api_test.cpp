// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "admin/admin_api.hpp"

using nlohmann::json;
using rfbsim::manager::admin_cluster_json;
using rfbsim::manager::admin_host_json;
using rfbsim::manager::admin_session_json;
using rfbsim::manager::admin_sessions_json;
using rfbsim::manager::ClusterPeer;
using rfbsim::manager::health_json;
using rfbsim::manager::ManagerConfig;
using rfbsim::manager::Session;
using rfbsim::manager::SessionState;

namespace {

Session live_session() {
  Session s;
  s.id = 7;
  s.uid = "p01";
  s.token = "0123456789abcdef0123456789abcdef";
  s.scenario = "lab";
  s.seed = 18446744073709551615ULL;
  s.state = SessionState::kRunning;
  s.params_json = R"({"uid":"p01","scenario":"lab"})";
  s.detail = "bad byte \xff here";
  return s;
}

}  // namespace

TEST_CASE("admin api: a session keeps its 64-bit seed as text, its parameters as an object, and any bytes") {
  const json session = json::parse(admin_session_json(live_session(), true));
  CHECK(session["id"] == 7);
  CHECK(session["seed"] == "18446744073709551615");
  CHECK(session["params"]["scenario"] == "lab");
  CHECK(session["token"] == "0123456789abcdef0123456789abcdef");
  CHECK(session["ros_namespace"].is_null());
  CHECK(session["codec"].is_null());
  CHECK(session["detail"].get<std::string>().find("here") != std::string::npos);
  CHECK_FALSE(json::parse(admin_session_json(live_session(), false)).contains("token"));
}

TEST_CASE("admin api: the stream shows to one decimal while someone watches, null otherwise") {
  Session s = live_session();
  s.stream = rfbsim::manager::StreamReport{};
  s.stream->codec = "tight";
  s.stream->rtt_ms = 12.46;
  s.stream->fps = 29.83;
  s.stream->clients = 1;
  json session = json::parse(admin_session_json(s, true));
  CHECK(session["codec"] == "tight");
  CHECK(session["rtt_ms"].get<double>() == Approx(12.5));
  CHECK(session["fps"].get<double>() == Approx(29.8));
  s.stream->clients = 0;
  session = json::parse(admin_session_json(s, true));
  CHECK(session["fps"].is_null());
}

TEST_CASE("admin api: the listing puts live sessions with tokens and only ended ones among the recent") {
  Session live = live_session();
  Session ended = live_session();
  ended.id = 3;
  ended.state = SessionState::kFinished;
  const json listing = json::parse(admin_sessions_json(4, true, {&live}, {live, ended}));
  CHECK(listing["capacity"] == 4);
  CHECK(listing["draining"] == true);
  REQUIRE(listing["live"].size() == 1);
  CHECK(listing["live"][0].contains("token"));
  REQUIRE(listing["recent"].size() == 1);
  CHECK(listing["recent"][0]["id"] == 3);
  CHECK_FALSE(listing["recent"][0].contains("token"));
}

TEST_CASE("admin api: host, health and cluster views") {
  const json host = json::parse(admin_host_json({"h1", "/h1", true, false, 2, 4}));
  CHECK(host == json::parse(R"({"host":"h1","prefix":"/h1","draining":true,"shutting_down":false,"live":2,"max":4})"));
  CHECK(json::parse(health_json(false, 1, 4)) == json::parse(R"({"status":"ok","live_sessions":1,"capacity":4})"));

  ManagerConfig single;
  single.host_id = "solo";
  CHECK(json::parse(admin_cluster_json(single))["hosts"] == json::parse(R"([{"id":"solo","prefix":""}])"));

  ManagerConfig cluster;
  cluster.host_id = "h1";
  cluster.path_prefix = "/first";
  cluster.cluster_peers = {ClusterPeer{"h1", "10.0.0.1", 9001}, ClusterPeer{"h2", "10.0.0.2", 9001}};
  const json hosts = json::parse(admin_cluster_json(cluster))["hosts"];
  CHECK(hosts == json::parse(R"([{"id":"h1","prefix":"/first"},{"id":"h2","prefix":"/h2"}])"));
}
