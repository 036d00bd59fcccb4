// SPDX-License-Identifier: GPL-2.0-or-later
// Takeovers under a storm of one's own upgrades: each newer browser takes the session over once, from the one
// before it. Browsers told 4001 that never answer the close (as a script that opens and forgets) are not told and
// counted again on every later upgrade, and the log's takeover lines are rate-limited.
#include <catch2/catch.hpp>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "abuse_clients.hpp"
#include "manager_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ManagerOptions;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;
namespace abuse = rfbsim::test::abuse;

namespace {

// The lines of `path` that contain `text`.
int lines_containing(const std::filesystem::path& path, const std::string& text) {
  std::ifstream in(path);
  std::string line;
  int count = 0;
  while (std::getline(in, line)) count += line.find(text) != std::string::npos ? 1 : 0;
  return count;
}

}  // namespace

TEST_CASE("30 upgrades to one's own session from one address are 29 takeovers and a few log lines",
          "[manager][abuse]") {
  TempDir data;
  TempDir logs;
  ManagerOptions options;
  options.log_file = logs.path() / "manager.log";
  ManagerUnderTest manager(data.path(), with_small_sessions({}), options);
  const std::string token = token_from_redirect(manager.start("uid=storm-1"));
  REQUIRE(token.size() == 32);
  REQUIRE(manager.wait_for_state(token, "running", 30s));
  constexpr int kUpgrades = 30;  // the default upgrade burst per address
  // Each one completes its RFB handshake, so its relay is open when the next arrives; none ever reads again, so
  // each one told 4001 keeps its socket half-closed for as long as this test holds it.
  std::vector<std::unique_ptr<abuse::RawWsRfbClient>> browsers;
  for (int i = 0; i < kUpgrades; ++i) {
    browsers.push_back(std::make_unique<abuse::RawWsRfbClient>("127.0.0.2", manager.port(), "/s/" + token + "/ws",
                                                               manager.origin()));
  }
  CHECK(manager.metric("rfbsim_takeovers_total") == kUpgrades - 1);
  CHECK(manager.state_of(token) == "running");
  const int takeover_lines = lines_containing(options.log_file, "a newer browser took over");
  INFO(takeover_lines << " takeover lines in the manager's log");
  CHECK(takeover_lines >= 1);
  CHECK(takeover_lines <= 40);
}
