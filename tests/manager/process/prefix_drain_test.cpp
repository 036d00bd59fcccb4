// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager behind a balancer, as a real process: under a path prefix (/h2) the link redirects into it and the
// page, status, socket and admin API answer there; the HAProxy agent-check port says how much room is left, or
// drain when full or drained by the operator; a drained host keeps serving its live sessions and their rejoins
// while new uids get the busy page; and a uid whose own session is still ending is told so, not "busy".
// Sessions are rfbsim_minimal (a legacy RFB program): cheap, and what is tested here is the manager.
#include <catch2/catch.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::admin_post;
using rfbsim::test::eventually;
using rfbsim::test::free_loopback_port;
using rfbsim::test::kAdminToken;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::WsRfbBridge;
namespace net = rfbsim::test::net;

namespace {

const std::vector<std::pair<std::string, std::string>> kAdmin = {{"Authorization", std::string("Bearer ") + kAdminToken}};

std::vector<std::string> minimal_flags(std::vector<std::string> more) {
  std::vector<std::string> flags = {"--session-kind", "rfb",         "--session-command", RFBSIM_MINIMAL,
                                    "--session-arg",  "{port}",      "--scenarios",       "demo",
                                    "--admin-token",  kAdminToken,   "--host-id",         "h2"};
  flags.insert(flags.end(), more.begin(), more.end());
  return rfbsim::test::without_abuse_limits(flags);
}

// What the agent on `port` says: everything it writes before it closes ("" when nothing answers).
std::string agent_line(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return "";
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval timeout{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  std::string text;
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0) {
    char buffer[256];
    for (ssize_t got; (got = ::recv(fd, buffer, sizeof buffer, 0)) > 0;) text.append(buffer, static_cast<std::size_t>(got));
  }
  ::close(fd);
  return text;
}

// The token of a 302 to `prefix`/s/<token>/ ("" for any other answer).
std::string token_under(const net::HttpResponse& response, const std::string& prefix) {
  const auto location = response.headers.find("location");
  if (response.status != 302 || location == response.headers.end()) return "";
  const std::string& value = location->second;
  const std::string head = prefix + "/s/";
  if (value.size() != head.size() + 33 || value.rfind(head, 0) != 0 || value.back() != '/') return "";
  return value.substr(head.size(), 32);
}

// The session's state from `prefix`/s/<token>/status ("" when it does not answer JSON).
std::string state_under(const ManagerUnderTest& manager, const std::string& prefix, const std::string& token) {
  const auto response = manager.get(prefix + "/s/" + token + "/status");
  const auto json = nlohmann::json::parse(response.body, nullptr, false);
  return response.status == 200 && json.is_object() ? json.value("state", "") : "";
}

}  // namespace

TEST_CASE("under a path prefix the link redirects into it, and the page, status and socket answer there",
          "[manager][cluster]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), minimal_flags({"--path-prefix", "/h2"}));
  // The balancer sends /start unprefixed; the redirect carries the host's prefix, which routes back here.
  const auto start = manager.start("uid=prefix-1");
  const std::string token = token_under(start, "/h2");
  REQUIRE(token.size() == 32);
  // Under the prefix, /start joins the same session (a registry's redirect to /h2/start lands here).
  CHECK(token_under(manager.get("/h2/start?uid=prefix-1"), "/h2") == token);

  const auto page = manager.get("/h2/s/" + token + "/");
  CHECK(page.status == 200);
  CHECK(page.headers.at("content-type").find("text/html") != std::string::npos);
  REQUIRE(eventually([&] { return state_under(manager, "/h2", token) == "running"; }, 20s));
  // The unprefixed paths still answer (a host reached directly), another host's prefix does not.
  CHECK(state_under(manager, "", token) == "running");
  CHECK(manager.get("/h1/s/" + token + "/status").status == 404);
  CHECK(manager.get("/h2x/s/" + token + "/status").status == 404);

  WsRfbBridge bridge("ws://127.0.0.1:" + std::to_string(manager.port()) + "/h2/s/" + token + "/ws");
  RfbTestClient client("127.0.0.1", bridge.port());
  CHECK(client.wait_for_updates(1, 20s));

  // The admin page and its API under the prefix; /admin/ goes to /admin, where its relative paths resolve.
  CHECK(manager.get("/h2/admin", kAdmin).status == 200);
  const auto slash = manager.get("/h2/admin/", kAdmin);
  CHECK(slash.status == 301);
  CHECK(slash.headers.at("location") == "../admin");
  CHECK(manager.get("/h2/admin/admin.js", kAdmin).status == 200);
  const auto sessions = manager.get("/h2/api/sessions", kAdmin);
  CHECK(sessions.status == 200);
  CHECK(sessions.body.find(token) != std::string::npos);
  const auto cluster = nlohmann::json::parse(manager.get("/h2/api/cluster", kAdmin).body, nullptr, false);
  REQUIRE(cluster.is_object());
  CHECK(cluster.value("self", "") == "h2");
  CHECK(cluster["hosts"] == nlohmann::json::parse(R"([{"id":"h2","prefix":"/h2"}])"));
}

TEST_CASE("the agent port says how much room is left, and drain when full or drained", "[manager][cluster]") {
  TempDir data;
  const int agent_port = free_loopback_port();
  ManagerUnderTest manager(data.path(),
                           minimal_flags({"--max-sessions", "2", "--agent-port", std::to_string(agent_port)}));
  CHECK(agent_line(agent_port) == "up ready 100%\n");
  CHECK(manager.get("/healthz").status == 200);

  const std::string a = rfbsim::test::token_from_redirect(manager.start("uid=agent-a"));
  REQUIRE(a.size() == 32);
  CHECK(agent_line(agent_port) == "up ready 50%\n");
  const std::string b = rfbsim::test::token_from_redirect(manager.start("uid=agent-b"));
  REQUIRE(b.size() == 32);
  CHECK(agent_line(agent_port) == "drain\n");  // full
  CHECK(manager.get("/healthz").status == 200);  // full is not draining: the host is healthy

  // A freed slot: ready again.
  const auto row = manager.row_for_token(b);
  REQUIRE(row);
  REQUIRE(manager.end_session(row->id, kAdminToken).status == 200);
  REQUIRE(eventually([&] { return agent_line(agent_port) == "up ready 50%\n"; }, 15s));

  // The operator drains the host: only the admin, and only with the admin header (no cross-site posts).
  CHECK(net::http_request(manager.port(), "POST /api/drain HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Rfbsim-Admin: 1\r\n"
                                          "Content-Length: 0\r\nConnection: close\r\n\r\n")
            .status == 401);
  CHECK(admin_post(manager, "/api/drain", false).status == 403);
  CHECK(manager.get("/api/drain", kAdmin).status == 405);
  CHECK(agent_line(agent_port) == "up ready 50%\n");
  const auto drained = admin_post(manager, "/api/drain");
  CHECK(drained.status == 200);
  const auto host = nlohmann::json::parse(drained.body, nullptr, false);
  REQUIRE(host.is_object());
  CHECK(host["draining"] == true);
  CHECK(host["host"] == "h2");
  CHECK(host["live"] == 1);
  CHECK(host["max"] == 2);
  CHECK(agent_line(agent_port) == "drain\n");
  const auto health = manager.get("/healthz");
  CHECK(health.status == 503);
  CHECK(health.body.find("draining") != std::string::npos);
  CHECK(nlohmann::json::parse(manager.get("/api/host", kAdmin).body, nullptr, false)["draining"] == true);
  CHECK(nlohmann::json::parse(manager.get("/api/sessions", kAdmin).body, nullptr, false)["draining"] == true);

  // And takes it back.
  CHECK(admin_post(manager, "/api/undrain").status == 200);
  CHECK(agent_line(agent_port) == "up ready 50%\n");
  CHECK(manager.get("/healthz").status == 200);
  CHECK(nlohmann::json::parse(manager.get("/api/sessions", kAdmin).body, nullptr, false)["draining"] == false);
}

TEST_CASE("a drained host serves its live sessions and their rejoins, and sends new uids away busy",
          "[manager][cluster]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), minimal_flags({"--max-sessions", "2", "--path-prefix", "/h2"}));
  const std::string token = token_under(manager.start("uid=drain-live"), "/h2");
  REQUIRE(token.size() == 32);
  REQUIRE(eventually([&] { return state_under(manager, "/h2", token) == "running"; }, 20s));
  WsRfbBridge bridge("ws://127.0.0.1:" + std::to_string(manager.port()) + "/h2/s/" + token + "/ws");
  RfbTestClient client("127.0.0.1", bridge.port());
  REQUIRE(client.wait_for_updates(1, 20s));

  REQUIRE(admin_post(manager, "/api/drain").status == 200);
  // A new uid: the busy page with Retry-After, which a balancer may send elsewhere (nothing was claimed here).
  const auto busy = manager.start("uid=drain-new");
  CHECK(busy.status == 503);
  CHECK(busy.headers.count("retry-after") == 1);
  CHECK(busy.body.find("All simulators are busy") != std::string::npos);
  // The live uid rejoins its session, whose page, status and socket go on.
  CHECK(token_under(manager.start("uid=drain-live"), "/h2") == token);
  CHECK(manager.get("/h2/s/" + token + "/").status == 200);
  CHECK(state_under(manager, "/h2", token) == "running");
  CHECK(client.wait_for_updates(1, 20s));
  WsRfbBridge second("ws://127.0.0.1:" + std::to_string(manager.port()) + "/h2/s/" + token + "/ws");
  RfbTestClient rejoined("127.0.0.1", second.port());
  CHECK(rejoined.wait_for_updates(1, 20s));

  REQUIRE(admin_post(manager, "/api/undrain").status == 200);
  CHECK(token_under(manager.start("uid=drain-new"), "/h2").size() == 32);
}

TEST_CASE("a uid whose own session is still ending is told so with 409, never the busy page",
          "[manager][cluster]") {
  TempDir data;
  // A session that outlives SIGTERM (its shell ignores it) stays "ending" until SIGKILL after the grace period.
  ManagerUnderTest manager(
      data.path(),
      rfbsim::test::without_abuse_limits({"--session-kind", "rfb", "--session-command", "/bin/sh", "--session-arg",
                                          "-c", "--session-arg", "trap '' TERM; \"$0\" \"$1\"; sleep 40",
                                          "--session-arg", RFBSIM_MINIMAL, "--session-arg", "{port}",
                                          "--scenarios", "demo", "--admin-token", kAdminToken,
                                          "--stop-grace-s", "30"}));
  const std::string token = rfbsim::test::token_from_redirect(manager.start("uid=closing-1"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  REQUIRE(manager.end_session(row->id, kAdminToken).status == 200);
  const auto again = manager.start("uid=closing-1");
  CHECK(again.status == 409);
  CHECK(again.headers.count("retry-after") == 1);
  CHECK(again.body.find("previous session is closing") != std::string::npos);
  CHECK(again.body.find("All simulators are busy") == std::string::npos);
}
