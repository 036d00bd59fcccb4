// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager under faults and load, with real processes on loopback: no descriptors left (EMFILE), a
// browser that stops reading, a frozen (SIGSTOPped) session, a session whose data cannot be written, and the
// manager killed with SIGKILL while a session starts. The manager stays responsive and leaves no orphan.
#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <csignal>
#include <fstream>
#include <string>

#include "abuse_clients.hpp"
#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::WsRfbBridge;
using rfbsim::test::eventually;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;
namespace abuse = rfbsim::test::abuse;

namespace {

// A wrapper that starts sim_manager with a descriptor limit of `limit`, soft and hard: the manager raises its
// soft limit to the hard one at start-up.
std::filesystem::path low_descriptor_wrapper(const std::filesystem::path& folder, int limit) {
  const std::filesystem::path script = folder / "sim_manager_low_fds.sh";
  std::ofstream out(script);
  out << "#!/bin/sh\nulimit -n " << limit << " || exit 97\nexec '" << rfbsim::test::sim_manager_path()
      << "' \"$@\"\n";
  out.close();
  ::chmod(script.c_str(), 0700);
  return script;
}

// A session started, connected to and shown pictures; its token.
std::string streamed_session(const ManagerUnderTest& manager, const std::string& uid) {
  const std::string token = token_from_redirect(manager.start("uid=" + uid));
  if (token.empty()) return token;
  WsRfbBridge bridge(manager.ws_url(token));
  RfbTestClient client("127.0.0.1", bridge.port());
  return client.wait_for_updates(2, 30s) ? token : "";
}

}  // namespace

TEST_CASE("at the descriptor limit the manager pauses accepting instead of spinning, and recovers",
          "[manager][faults]") {
  TempDir data;
  TempDir bin;
  rfbsim::test::ManagerOptions options;
  options.program = low_descriptor_wrapper(bin.path(), 128).string();
  // Caps far above what 128 descriptors allow: the limit itself, not the caps, meets the flood. Sessions keep the
  // hard 128 they inherit: without root, the default (1024) could not be set above it.
  ManagerUnderTest manager(data.path(),
                           with_small_sessions({"--max-connections", "1000", "--max-connections-per-address", "1000",
                                                "--max-sessions", "1", "--limit-open-files", "0"}),
                           options);
  const auto flood_began = std::chrono::steady_clock::now();
  {
    // More than the manager can hold; the rest waits in the listen backlog (256).
    abuse::IdleConnections flood("127.0.0.2", manager.port(), 200);
    // Those it took are closed by the 5 s handshake timeout and the backlog refills them: measure at once.
    const double cpu_before = abuse::process_cpu_seconds(manager.pid());
    std::this_thread::sleep_for(2s);
    const double cpu_used = abuse::process_cpu_seconds(manager.pid()) - cpu_before;
    INFO("the manager used " << cpu_used << " s of CPU in 2 s at the descriptor limit");
    CHECK(cpu_used < 0.5);  // a spinning accept loop would use a whole core: ~2 s
  }
  // The flood is gone: the manager answers and starts sessions again.
  REQUIRE(eventually([&] { return manager.get("/healthz").status == 200; }, 30s));
  const double errors = manager.metric("rfbsim_accept_errors_total");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - flood_began).count();
  INFO(errors << " failed accepts in " << seconds << " s");
  CHECK(errors > 0);
  // One try per 100 ms pause at most (twice that for slack); a spin makes hundreds of thousands a second.
  CHECK(errors <= seconds * 20 + 10);
  CHECK_FALSE(streamed_session(manager, "emfile-real").empty());
}

TEST_CASE("a browser that stops reading costs the manager no memory, and other sessions keep streaming",
          "[manager][faults][waits]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({}));
  const std::string slow_token = token_from_redirect(manager.start("uid=slow-reader"));
  const std::string other_token = token_from_redirect(manager.start("uid=other-viewer"));
  REQUIRE(slow_token.size() == 32);
  REQUIRE(other_token.size() == 32);
  REQUIRE(manager.wait_for_state(slow_token, "running"));
  WsRfbBridge bridge(manager.ws_url(other_token));
  RfbTestClient other("127.0.0.1", bridge.port());
  REQUIRE(other.wait_for_updates(2, 30s));

  abuse::RawWsRfbClient slow("127.0.0.2", manager.port(), "/s/" + slow_token + "/ws", manager.origin());
  slow.set_raw_encoding();
  const long rss_before = abuse::resident_kib(manager.pid());
  // Whole Raw pictures asked for again and again (300 KiB each at 320x240) and never read, while the other
  // participant keeps pulling pictures.
  const std::uint64_t other_before = other.updates();
  for (int i = 0; i < 60; ++i) {
    slow.request_full_update();
    other.pump_until([] { return false; }, 100ms);
  }
  const long rss_after = abuse::resident_kib(manager.pid());
  INFO("manager VmRSS " << rss_before << " KiB -> " << rss_after << " KiB; the slow client has "
                        << slow.unread_bytes() << " bytes unread");
  CHECK(slow.unread_bytes() > 0);              // pictures did come, and wait unread
  CHECK(rss_after - rss_before < 5 * 1024);    // held back by flow control, not buffered in the manager
  CHECK(other.updates() - other_before >= 5);  // the other session went on
  CHECK(other.connected());
  CHECK(manager.state_of(slow_token) == "running");
}

TEST_CASE("a SIGSTOPped session does not stall the manager, and is still killed at its maximum duration",
          "[manager][faults][waits]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), with_small_sessions({"--max-duration-s", "8", "--stop-grace-s", "2"}));
  const std::string frozen = streamed_session(manager, "frozen-1");  // seen: it ends expired, not abandoned
  REQUIRE(frozen.size() == 32);
  // The index is written on its own thread: wait for the row rather than expect it at once.
  const auto row = manager.wait_for_row(frozen, [](const auto& r) { return r.pid > 1; }, 10s);
  REQUIRE(row);
  const auto pid = static_cast<pid_t>(row->pid);
  REQUIRE(::kill(pid, SIGSTOP) == 0);

  CHECK(manager.get("/healthz").status == 200);
  CHECK_FALSE(streamed_session(manager, "lively-1").empty());

  // SIGTERM at 8 s does nothing to a stopped process; SIGKILL after the 2 s grace does.
  REQUIRE(manager.wait_for_state(frozen, "expired", 60s));
  const auto ended = manager.wait_for_row(frozen, [](const auto& r) { return r.state == "expired"; }, 10s);
  REQUIRE(ended);
  CHECK(ended->exit_status == "signal 9");
  CHECK(ended->detail == "reached the maximum duration of 8 s");
  CHECK_FALSE(rfbsim::test::process_exists(pid));
  CHECK_FALSE(rfbsim::test::group_has_running_member(pid));
  CHECK(manager.get("/healthz").status == 200);
}

TEST_CASE("a session whose data cannot be written is marked data_incomplete, and ends when so configured",
          "[manager][faults]") {
  // Reaches sim_rfb through the manager's allow-list (RFBSIM_ variables pass): its data writes fail with
  // ENOSPC after this many bytes.
  abuse::ScopedEnv fail_writes("RFBSIM_TEST_FAIL_WRITES_AFTER", "4000");
  TempDir data;

  SECTION("continue (the default): recorded, and the participant carries on") {
    ManagerUnderTest manager(data.path(), with_small_sessions({}));
    const std::string token = token_from_redirect(manager.start("uid=full-disk-1"));
    REQUIRE(token.size() == 32);
    std::string reason;
    REQUIRE(eventually(
        [&] {
          reason = abuse::index_column(data.path(), token, "data_incomplete");
          return !reason.empty();
        },
        60s));
    CHECK_THAT(reason, Catch::Contains("No space left on device"));
    WsRfbBridge bridge(manager.ws_url(token));
    RfbTestClient client("127.0.0.1", bridge.port());
    CHECK(client.wait_for_updates(2, 30s));
    CHECK(manager.state_of(token) == "running");
  }

  SECTION("end: the session ends, and the reason is kept") {
    ManagerUnderTest manager(data.path(), with_small_sessions({"--on-data-incomplete", "end"}));
    const std::string token = token_from_redirect(manager.start("uid=full-disk-2"));
    REQUIRE(token.size() == 32);
    // Nobody saw it, so it ends abandoned (a seen one ends "ended"): the link is not used up.
    REQUIRE(manager.wait_for_state(token, "abandoned", 60s));
    const auto row = manager.wait_for_row(token, [](const auto& r) { return r.state == "abandoned"; }, 10s);
    REQUIRE(row);
    const std::string reason = abuse::index_column(data.path(), token, "data_incomplete");
    CHECK_THAT(reason, Catch::Contains("No space left on device"));
    CHECK(row->detail == "the session's data could not be written: " + reason);
    CHECK(manager.children().empty());
  }
}

TEST_CASE("a manager killed with SIGKILL right after a /start leaves no process, and its successor says so",
          "[manager][faults]") {
  TempDir data;
  std::string token;
  pid_t session_pid = 0;
  {
    ManagerUnderTest manager(data.path(), with_small_sessions({}));
    token = token_from_redirect(manager.start("uid=mid-start"));
    REQUIRE(token.size() == 32);
    // From /proc, not the index: the row's pid may still be queued for writing when the manager dies.
    std::vector<pid_t> children;
    REQUIRE(eventually(
        [&] {
          children = manager.children();
          return children.size() == 1;
        },
        5s, 1ms));
    session_pid = children.front();
    REQUIRE(manager.process().stop(SIGKILL) != -1);  // the session is still starting (sim_rfb takes ~1 s)
    const auto row = manager.row_for_token(token);
    REQUIRE(row);  // the redirect came after the row was recorded
    if (row->state != "starting") WARN("the kill came after the session was ready (" << row->state << ")");
  }
  REQUIRE(session_pid > 1);
  CHECK(eventually([&] { return !rfbsim::test::process_exists(session_pid); }, 10s));
  CHECK_FALSE(rfbsim::test::group_has_running_member(session_pid));

  ManagerUnderTest successor(data.path(), with_small_sessions({}));
  const auto row = successor.wait_for_row(token, [](const auto& r) { return r.state == "interrupted"; }, 10s);
  REQUIRE(row);
  CHECK(row->state == "interrupted");
  CHECK(row->detail == "the manager stopped unexpectedly while the session ran");
  CHECK_FALSE(row->ended_at.empty());
  // Not the participant's doing: the same link starts afresh.
  const std::string again = token_from_redirect(successor.start("uid=mid-start"));
  CHECK(again.size() == 32);
  CHECK(again != token);
}
