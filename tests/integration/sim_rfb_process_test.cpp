// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb as a real process: a real RFB client walks the avatar; command-line and setup errors.
#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "rfb_test_client.hpp"
#include "rfbsim/server.hpp"
#include "sim_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::http_body;
using rfbsim::test::http_get;
using rfbsim::test::json_number;
using rfbsim::test::RfbTestClient;
using rfbsim::test::SimProcess;

namespace {

std::string status_of(const SimProcess& sim) { return http_body(http_get(sim.port(), "/status.json")); }

// Polls /status.json (while pumping the client, if any) until `done(status)` holds or 10 s pass.
template <typename Done>
bool await_status(const SimProcess& sim, RfbTestClient* client, Done done, std::string& status) {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < deadline) {
    status = status_of(sim);
    if (done(status)) return true;
    if (client != nullptr) client->pump_until([] { return false; }, 50ms);
    else std::this_thread::sleep_for(50ms);  // the sim advances on its own clock
  }
  return false;
}

const std::vector<std::string> kSmall = {"--port", "0", "--width", "320", "--height", "240"};

}  // namespace

TEST_CASE("holding W walks the avatar and changes the picture") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);
  std::string status;
  // Nobody watches yet: the simulation ticks but renders nothing.
  REQUIRE(await_status(sim, nullptr, [](const std::string& s) { return json_number(s, "tick") > 10; }, status));
  CHECK(json_number(status, "frames_rendered") == 0);
  const double y0 = json_number(status, "y");

  auto client = std::make_unique<RfbTestClient>("127.0.0.1", sim.port());
  REQUIRE(client->width() == 320);
  // Wait for a real picture: the sky above (blue over red) and the floor below.
  REQUIRE(client->pump_until([&] { return client->frame().row(5)[2] > client->frame().row(5)[0] + 20; }, 10s));
  // The standing avatar's picture is static, so no further update is due: this is the reference.
  std::vector<std::uint8_t> before(client->frame().pixels, client->frame().pixels + 320 * 240 * 4);

  client->send_key('w', true);
  REQUIRE(await_status(sim, client.get(), [&](const std::string& s) { return json_number(s, "y") > y0 + 1.0; }, status));
  client->send_key('w', false);
  CHECK(std::abs(json_number(status, "x") - 3.5) < 1e-6);  // straight ahead, along +y
  // The picture follows the walk: the floor tiles slide under the camera.
  CHECK(client->pump_until(
      [&] { return rfbsim::test::mean_abs_difference(client->frame(), {before.data(), 320, 240, 0}) > 5.0; }, 10s));
  REQUIRE(await_status(sim, client.get(), [](const std::string& s) { return json_number(s, "speed") == 0.0; }, status));

  // Disconnect: rendering stops while nobody watches.
  client.reset();
  REQUIRE(await_status(sim, nullptr, [](const std::string& s) { return json_number(s, "clients") == 0; }, status));
  const double frames = json_number(status, "frames_rendered");
  const double tick = json_number(status, "tick");
  CHECK(frames > 0);
  REQUIRE(await_status(sim, nullptr, [&](const std::string& s) { return json_number(s, "tick") > tick + 30; }, status));
  CHECK(json_number(status, "frames_rendered") == frames);

  // Reconnect: a new client gets the picture again.
  RfbTestClient again("127.0.0.1", sim.port());
  CHECK(again.wait_for_updates(1, 10s));

  const int exit_status = sim.stop(SIGTERM);
  REQUIRE(exit_status != -1);
  CHECK(WIFEXITED(exit_status));
  CHECK(WEXITSTATUS(exit_status) == 0);
}

TEST_CASE("a client that leaves with W held does not leave the avatar walking") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);
  std::string status;
  {
    RfbTestClient client("127.0.0.1", sim.port());
    client.send_key('W', true);
    REQUIRE(await_status(sim, &client, [](const std::string& s) { return json_number(s, "speed") > 1.0; }, status));
  }  // gone without releasing W
  REQUIRE(await_status(sim, nullptr, [](const std::string& s) { return json_number(s, "speed") == 0.0; }, status));
  const double y = json_number(status, "y");
  std::string later;
  REQUIRE(await_status(sim, nullptr, [&](const std::string& s) {
    return json_number(s, "tick") > json_number(status, "tick") + 30; }, later));
  CHECK(json_number(later, "y") == y);
}

TEST_CASE("bad command lines and setup failures exit with a clear message") {
  const auto bad_port = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--port", "banana"});
  CHECK(WIFEXITED(bad_port.status));
  CHECK(WEXITSTATUS(bad_port.status) == 2);
  CHECK_THAT(bad_port.output, Catch::Contains("bad value 'banana' for --port"));

  const auto unknown = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--fly"});
  CHECK(WEXITSTATUS(unknown.status) == 2);
  CHECK_THAT(unknown.output, Catch::Contains("unknown argument '--fly'"));

  // The port is taken by another server.
  rfbsim::ServerOptions holder_options;
  holder_options.width = holder_options.height = 64;
  rfbsim::Server holder(holder_options);
  const auto taken = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(),
                                               {"--port", std::to_string(holder.port()), "--width", "320", "--height", "240"});
  CHECK(WEXITSTATUS(taken.status) == 1);
  CHECK_THAT(taken.output, Catch::Contains("port " + std::to_string(holder.port()) + " is already in use"));

  const auto no_page = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--port", "0", "--web-root", "/nonexistent"});
  CHECK(WEXITSTATUS(no_page.status) == 1);
  CHECK_THAT(no_page.output, Catch::Contains("no index.html"));

  // Scenarios: a misspelt name, a bad override and a broken file each end it with 2 and say why.
  const auto unknown_scenario = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(),
                                                          {"--port", "0", "--scenario", "warhouse"});
  CHECK(WEXITSTATUS(unknown_scenario.status) == 2);
  CHECK_THAT(unknown_scenario.output, Catch::Contains("scenario 'warhouse' not found") &&
                                          Catch::Contains("warehouse") && Catch::Contains("lab"));
  const auto bad_start = rfbsim::test::run_to_exit(
      rfbsim::test::sim_rfb_path(), {"--port", "0", "--scenario", "lab", "--avatar-start", "1,2,3,4"});
  CHECK(WEXITSTATUS(bad_start.status) == 2);
  CHECK_THAT(bad_start.output, Catch::Contains("--avatar-start: '1,2,3,4'"));
  const auto broken = std::filesystem::temp_directory_path() / ("rfbsim_broken_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(broken) << "map: lab.yaml\navatar:\n  start: [1, 1]\ncrowd: {count: x}\n";
  const auto broken_file = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(),
                                                     {"--port", "0", "--scenario", broken.string()});
  std::filesystem::remove(broken);
  CHECK(WEXITSTATUS(broken_file.status) == 2);
  CHECK_THAT(broken_file.output, Catch::Contains(broken.string()) && Catch::Contains("key 'map'"));
  CHECK_THAT(broken_file.output, !Catch::Contains("ready"));

  const auto help = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--help"});
  CHECK(WEXITSTATUS(help.status) == 0);
  CHECK_THAT(help.output, Catch::Contains("usage: sim_rfb"));
}
