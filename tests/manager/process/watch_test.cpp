// SPDX-License-Identifier: GPL-2.0-or-later
// A researcher watching a session from the admin page: the view is relayed view-only (the watcher's keys and
// clicks never reach the session, the participant's do), it needs the admin token, it is framed by no survey,
// a watcher does not keep an idle session alive, and it does not start the participant's task clock.
#include <catch2/catch.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "file_text.hpp"
#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "skip.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::eventually;
using rfbsim::test::kAdminToken;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;
using rfbsim::test::WsRfbBridge;
using rfbsim::test::WsRfbBridgeOptions;

namespace {

const std::string kBearer = std::string("Bearer ") + kAdminToken;
const char* const kStdbuf = "/usr/bin/stdbuf";

// rfbsim_minimal as a legacy session: it prints every key and every click it gets on its stdout, which is the
// session's log. Through stdbuf -oL each line is written as it is printed (a log file is block-buffered).
std::vector<std::string> minimal_session_flags(std::vector<std::string> more = {}) {
  std::vector<std::string> flags = {"--session-kind", "rfb",          "--session-command", kStdbuf,
                                    "--session-arg",  "-oL",          "--session-arg",     RFBSIM_MINIMAL,
                                    "--session-arg",  "{port}",       "--scenarios",       "demo",
                                    "--admin-token",  kAdminToken};
  flags.insert(flags.end(), more.begin(), more.end());
  return flags;
}

// The lines of a session's events.jsonl written so far (a line still being written is left out).
std::vector<nlohmann::json> read_events(const std::filesystem::path& file) {
  std::vector<nlohmann::json> events;
  std::istringstream lines(rfbsim::test::file_text(file));
  std::string line;
  while (std::getline(lines, line)) {
    nlohmann::json event = nlohmann::json::parse(line, nullptr, false);
    if (!event.is_discarded()) events.push_back(std::move(event));
  }
  return events;
}

// Where in `events` the first one of `type` (and, if given, with "event": `what`) is; -1 if none.
int index_of(const std::vector<nlohmann::json>& events, const std::string& type, const std::string& what = "",
             int from = 0) {
  for (int i = from; i < static_cast<int>(events.size()); ++i) {
    const auto& e = events[static_cast<std::size_t>(i)];
    if (e.value("type", "") == type && (what.empty() || e.value("event", "") == what)) return i;
  }
  return -1;
}

// The watch WebSocket of session `token`, and bridge options that send `authorization` on its handshake.
std::string watch_url(const ManagerUnderTest& manager, const std::string& token) {
  return "ws://127.0.0.1:" + std::to_string(manager.port()) + "/admin/watch/" + token + "/ws";
}

WsRfbBridgeOptions with_authorization(const std::string& authorization) {
  WsRfbBridgeOptions options;
  if (!authorization.empty()) options.extra_headers = {{"Authorization", authorization}};
  return options;
}

// The handshake status a watch socket gets with these options (the connection is refused or dropped at once).
int watch_handshake_status(const ManagerUnderTest& manager, const std::string& token, WsRfbBridgeOptions options) {
  WsRfbBridge bridge(watch_url(manager, token), std::move(options));
  CHECK_THROWS(RfbTestClient("127.0.0.1", bridge.port()));
  REQUIRE(bridge.wait_last_finished(5s));
  return bridge.last_handshake_status();
}

// Connects to 127.0.0.1:`port` and sends `bytes`; returns the socket (the caller closes it), -1 on failure.
int send_raw(int port, const std::string& bytes) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 ||
      ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(bytes.size())) {
    ::close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

TEST_CASE("a watcher sees the session, but its keys and clicks never reach it", "[manager][watch]") {
  if (!std::filesystem::exists(kStdbuf)) RFBSIM_SKIP(std::string(kStdbuf) + " is missing (Debian's coreutils)");
  TempDir data;
  ManagerUnderTest manager(data.path(), minimal_session_flags());
  const std::string token = token_from_redirect(manager.start("uid=watch-1"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  const std::filesystem::path log = std::filesystem::path(row->data_path) / "session.log";

  WsRfbBridge participant_bridge(manager.ws_url(token));
  RfbTestClient participant("127.0.0.1", participant_bridge.port());
  REQUIRE(participant.wait_for_updates(1, 20s));
  WsRfbBridge watch_bridge(watch_url(manager, token), with_authorization(kBearer));
  RfbTestClient watcher("127.0.0.1", watch_bridge.port());
  REQUIRE(watcher.wait_for_updates(1, 20s));
  CHECK(watcher.width() == 640);  // rfbsim_minimal's picture, as the participant sees it
  CHECK(watcher.height() == 480);
  CHECK(manager.metric("rfbsim_relay_connections{kind=\"participant\"}") == 1);
  CHECK(manager.metric("rfbsim_relay_connections{kind=\"watch\"}") == 1);
  CHECK(manager.metric("rfbsim_relay_connections_total{kind=\"watch\"}") == 1);

  // The watcher types 'x' and clicks. Two more updates mean the session answered an update request the
  // watcher sent after them, so the session would have read them by now had the relay passed them on.
  watcher.send_key('x', true);
  watcher.send_key('x', false);
  watcher.send_pointer(20, 30, 1);
  watcher.send_pointer(20, 30, 0);
  REQUIRE(watcher.wait_for_updates(2, 20s));
  // Then the participant clicks and types 'p': once those show in the log, anything before them would too.
  participant.send_pointer(40, 50, 1);
  participant.send_pointer(40, 50, 0);
  participant.send_key('p', true);
  participant.send_key('p', false);
  REQUIRE(eventually([&] { return rfbsim::test::file_text(log).find("key 0x70 up") != std::string::npos; }, 10s));
  const std::string text = rfbsim::test::file_text(log);
  INFO("session log:\n" << text);
  CHECK(text.find("key 0x70 down") != std::string::npos);
  CHECK(text.find("pointer 40,50 buttons 1") != std::string::npos);
  CHECK(text.find("key 0x78") == std::string::npos);
  CHECK(text.find("pointer 20,30") == std::string::npos);

  // Both views go on; the watcher's connection is no participant's.
  CHECK(watcher.wait_for_updates(1, 20s));
  CHECK(participant.wait_for_updates(1, 20s));
  CHECK(manager.state_of(token) == "running");
}

TEST_CASE("the watch page, status and socket need the admin token", "[manager][watch]") {
  TempDir data;
  ManagerUnderTest manager(
      data.path(), with_small_sessions({"--admin-token", kAdminToken, "--frame-origins", "https://survey.example"}));
  const std::string token = token_from_redirect(manager.start("uid=watch-auth"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  const std::string page = "/admin/watch/" + token + "/";
  const std::vector<std::pair<std::string, std::string>> admin = {{"Authorization", kBearer}};

  SECTION("without the token: 401 and a Basic challenge, for the page, its files, its status and its socket") {
    const auto anonymous = manager.get(page);
    CHECK(anonymous.status == 401);
    CHECK(anonymous.headers.at("www-authenticate").find("Basic") != std::string::npos);
    CHECK(manager.get(page + "app.bundle.js").status == 401);
    CHECK(manager.get(page + "status").status == 401);
    CHECK(manager.get(page, {{"Authorization", "Bearer wrong-token-wrong-token"}}).status == 401);
    CHECK(watch_handshake_status(manager, token, with_authorization("")) == 401);
    CHECK(watch_handshake_status(manager, token, with_authorization("Bearer wrong-token-wrong-token")) == 401);
    CHECK(manager.metric("rfbsim_relay_connections_total{kind=\"watch\"}") == 0);
  }

  SECTION("with the token: the participant's page, framed by the manager only") {
    const auto watched = manager.get(page, admin);
    const auto own = manager.get("/s/" + token + "/");
    REQUIRE(watched.status == 200);
    REQUIRE(own.status == 200);
    CHECK(watched.body == own.body);
    CHECK(watched.body.find("app.bundle.js") != std::string::npos);
    CHECK(watched.headers.at("content-security-policy") == "frame-ancestors 'self'");
    CHECK(own.headers.at("content-security-policy") == "frame-ancestors 'self' https://survey.example");
    CHECK(watched.headers.at("referrer-policy") == "no-referrer");
    const auto bundle = manager.get(page + "app.bundle.js", admin);
    CHECK(bundle.status == 200);
    CHECK(bundle.headers.at("content-type").find("javascript") != std::string::npos);
    CHECK(manager.get(page + "style.css", admin).status == 200);
    CHECK(manager.get(page + "no-such-file.js", admin).status == 404);
    CHECK(manager.get(page + "ws", admin).status == 400);  // WebSocket only
    const auto status = manager.get(page + "status", admin);
    CHECK(status.status == 200);
    CHECK(status.body.find("\"state\":\"running\"") != std::string::npos);
  }

  SECTION("the socket takes the token as Basic credentials too (what a browser resends), from its own origin") {
    // base64("researcher:test-admin-token-0123456789")
    WsRfbBridgeOptions basic = with_authorization("Basic cmVzZWFyY2hlcjp0ZXN0LWFkbWluLXRva2VuLTAxMjM0NTY3ODk=");
    basic.origin = manager.origin();
    WsRfbBridge bridge(watch_url(manager, token), basic);
    RfbTestClient watcher("127.0.0.1", bridge.port());
    CHECK(watcher.wait_for_updates(1, 20s));
    CHECK(bridge.last_handshake_status() == 101);
  }

  SECTION("no other origin may open the socket, a survey's included") {
    WsRfbBridgeOptions survey = with_authorization(kBearer);
    survey.origin = "https://survey.example";
    CHECK(watch_handshake_status(manager, token, survey) == 403);
    WsRfbBridgeOptions stranger = with_authorization(kBearer);
    stranger.origin = "https://evil.example";
    CHECK(watch_handshake_status(manager, token, stranger) == 403);
  }

  SECTION("an unknown session is not found; an ended one is gone, as for the participant") {
    const std::string unknown = "0123456789abcdef0123456789abcdef";
    CHECK(manager.get("/admin/watch/" + unknown + "/", admin).status == 404);
    CHECK(watch_handshake_status(manager, unknown, with_authorization(kBearer)) == 404);
    const auto row = manager.row_for_token(token);
    REQUIRE(row);
    REQUIRE(manager.end_session(row->id, kAdminToken).status == 200);
    // Only a watcher ever saw it: no participant spent the link, so it is abandoned, not ended.
    REQUIRE(manager.wait_for_state(token, "abandoned"));
    CHECK(manager.get(page, admin).status == 410);
    CHECK(manager.get("/s/" + token + "/").status == 410);
    CHECK(watch_handshake_status(manager, token, with_authorization(kBearer)) == 410);
  }
}

TEST_CASE("a watcher whose stream cannot be framed is closed with 1008 and the reason", "[manager][watch]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--admin-token", kAdminToken}));
  const std::string token = token_from_redirect(manager.start("uid=watch-garbage"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  WsRfbBridge bridge(watch_url(manager, token), with_authorization(kBearer));
  // A 3.8 handshake with security None, then message type 7, which no client sends to rfbsim: the filter
  // cannot tell where it ends, so it cannot tell what follows it either.
  const std::string stream = std::string("RFB 003.008\n") + '\x01' + '\x01' + std::string("\x07\x00\x00\x00", 4);
  const int fd = send_raw(bridge.port(), stream);
  REQUIRE(fd >= 0);
  const bool finished = bridge.wait_last_finished(10s);
  ::close(fd);
  REQUIRE(finished);
  CHECK(bridge.last().opened);
  CHECK(bridge.last_close_code() == 1008);
  CHECK(bridge.last_close_reason() == "unknown RFB client message type 7");
  // Only that watcher: the session runs on, and a participant is served as before.
  CHECK(manager.state_of(token) == "running");
  WsRfbBridge participant_bridge(manager.ws_url(token));
  RfbTestClient participant("127.0.0.1", participant_bridge.port());
  CHECK(participant.wait_for_updates(1, 20s));
}

TEST_CASE("without an admin token configured there is nothing to watch", "[manager][watch]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), rfbsim::test::small_session_args());
  const std::string token = token_from_redirect(manager.start("uid=watch-off"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  CHECK(manager.get("/admin/watch/" + token + "/", {{"Authorization", kBearer}}).status == 404);
  CHECK(watch_handshake_status(manager, token, with_authorization(kBearer)) == 404);
}

TEST_CASE("a session with only a watcher connected still ends as idle", "[manager][watch]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--admin-token", kAdminToken, "--idle-timeout-s", "1"}));
  const std::string token = token_from_redirect(manager.start("uid=watch-idle"));
  REQUIRE(token.size() == 32);
  // The participant keeps the session alive while the watcher joins (so the watcher is surely in before
  // the idle clock could run out), then leaves.
  auto participant_bridge = std::make_unique<WsRfbBridge>(manager.ws_url(token));
  auto participant = std::make_unique<RfbTestClient>("127.0.0.1", participant_bridge->port());
  REQUIRE(participant->wait_for_updates(1, 20s));
  WsRfbBridge watch_bridge(watch_url(manager, token), with_authorization(kBearer));
  RfbTestClient watcher("127.0.0.1", watch_bridge.port());
  REQUIRE(watcher.wait_for_updates(1, 20s));
  participant.reset();
  participant_bridge.reset();

  // The watcher keeps reading frames until the manager ends the session for want of a participant.
  watcher.pump_until([&] { return !watcher.connected(); }, 15s);
  REQUIRE(watch_bridge.wait_last_finished(5s));
  CHECK(watch_bridge.last_close_code() == 1001);
  CHECK(watch_bridge.last_close_reason() == "session ended after being idle");
  REQUIRE(manager.wait_for_state(token, "idle"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  CHECK(row->detail == "no browser connected for 1 s");
}

TEST_CASE("a researcher watching first does not start the participant's task clock, and the participant does",
          "[manager][watch][study]") {
  TempDir data;
  ManagerUnderTest manager(data.path(),
                           with_small_sessions({"--admin-token", kAdminToken, "--first-connect-timeout-s", "120"}));
  // The warehouse has a task, so its clock starts (a "timer" event) with the participant's first look.
  const std::string token = token_from_redirect(manager.start("uid=watch-clock&scenario=warehouse"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running"));
  const auto row = manager.row_for_token(token);
  REQUIRE(row);
  const std::filesystem::path events_file = std::filesystem::path(row->data_path) / "events.jsonl";

  // The researcher opens the session before the participant: the session records the watcher's connect
  // (the relay's PROXY line marked it view-only) and no timer.
  WsRfbBridge watch_bridge(watch_url(manager, token), with_authorization(kBearer));
  RfbTestClient watcher("127.0.0.1", watch_bridge.port());
  REQUIRE(watcher.wait_for_updates(1, 20s));
  REQUIRE(eventually(
      [&] {
        watcher.pump_until([] { return false; }, 50ms);
        return index_of(read_events(events_file), "client", "connect") >= 0;
      },
      20s));
  watcher.pump_until([] { return false; }, 1s);  // a few more ticks, in which a started clock would show
  const auto watched = read_events(events_file);
  INFO("events.jsonl while only the watcher is there:\n" << rfbsim::test::file_text(events_file));
  const int watcher_connect = index_of(watched, "client", "connect");
  REQUIRE(watcher_connect >= 0);
  CHECK(watched[static_cast<std::size_t>(watcher_connect)].value("role", "") == "watcher");
  CHECK(index_of(watched, "timer") < 0);
  CHECK(index_of(watched, "task", "started") < 0);

  // Then the participant: the clock starts at its connect.
  WsRfbBridge participant_bridge(manager.ws_url(token));
  RfbTestClient participant("127.0.0.1", participant_bridge.port());
  REQUIRE(participant.wait_for_updates(1, 20s));
  REQUIRE(eventually(
      [&] {
        watcher.pump_until([] { return false; }, 25ms);
        participant.pump_until([] { return false; }, 25ms);
        return index_of(read_events(events_file), "timer", "started") >= 0;
      },
      20s));
  const auto events = read_events(events_file);
  INFO("events.jsonl:\n" << rfbsim::test::file_text(events_file));
  REQUIRE(index_of(events, "client", "connect") == watcher_connect);
  const int participant_connect = index_of(events, "client", "connect", watcher_connect + 1);
  REQUIRE(participant_connect > watcher_connect);
  const auto& joined = events[static_cast<std::size_t>(participant_connect)];
  CHECK_FALSE(joined.contains("role"));  // a participant's connect is written as it always was
  const int timer = index_of(events, "timer", "started");
  CHECK(timer > participant_connect);
  CHECK(index_of(events, "timer", "started", timer + 1) < 0);  // once
  CHECK(events[static_cast<std::size_t>(timer)]["tick"] == joined["tick"]);
  CHECK(events[static_cast<std::size_t>(timer)]["tick"].get<std::uint64_t>() >
        events[static_cast<std::size_t>(watcher_connect)]["tick"].get<std::uint64_t>());
  CHECK(manager.state_of(token) == "running");
}
