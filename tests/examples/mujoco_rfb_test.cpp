// SPDX-License-Identifier: GPL-2.0-or-later
// mujoco_rfb as a real process: a real libvncclient client sees MuJoCo's picture of the arm on its table,
// the picture holds still with no key and changes when W is held (the arm's shoulder moves), the pointer zooms
// and orbits the camera, SIGTERM ends it with status 0, and bad command lines and models are refused with a
// clear message.
#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <set>
#include <vector>

#include "rfb_test_client.hpp"
#include "scratch_dir.hpp"
#include "sim_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::RfbTestClient;
using rfbsim::test::ScratchDir;
using rfbsim::test::SimProcess;

namespace {

constexpr int kChangedPixelThreshold = 48;  // |dR| + |dG| + |dB| above this counts as a changed pixel

// A copy of the client's picture (its frame() buffer changes with every update).
std::vector<std::uint8_t> copy_of(const rfbsim::FrameView& f) {
  std::vector<std::uint8_t> pixels;
  for (int y = 0; y < f.height; ++y) pixels.insert(pixels.end(), f.row(y), f.row(y) + f.width * 4);
  return pixels;
}

// The share of pixels (0..1) whose colour differs by more than kChangedPixelThreshold.
double changed_fraction(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  REQUIRE(a.size() == b.size());
  std::size_t changed = 0;
  for (std::size_t i = 0; i + 3 < a.size(); i += 4) {
    int diff = 0;
    for (std::size_t c = 0; c < 3; ++c) diff += std::abs(int{a[i + c]} - int{b[i + c]});
    if (diff > kChangedPixelThreshold) ++changed;
  }
  return static_cast<double>(changed) / static_cast<double>(a.size() / 4);
}

// Distinct colours (quantised to 5 bits a channel) and the luma range over the picture.
std::pair<std::size_t, int> variety(const std::vector<std::uint8_t>& pixels) {
  std::set<std::uint32_t> colours;
  int low = 255;
  int high = 0;
  for (std::size_t i = 0; i + 3 < pixels.size(); i += 4) {
    colours.insert((std::uint32_t{pixels[i]} >> 3) << 10 | (std::uint32_t{pixels[i + 1]} >> 3) << 5 |
                   std::uint32_t{pixels[i + 2]} >> 3);
    const int luma = (299 * pixels[i] + 587 * pixels[i + 1] + 114 * pixels[i + 2]) / 1000;
    low = std::min(low, luma);
    high = std::max(high, luma);
  }
  return {colours.size(), high - low};
}

// Writes the picture as a binary PPM into $RFBSIM_TEST_ARTIFACTS, when set, to look at by eye.
void keep_picture(const std::vector<std::uint8_t>& pixels, int width, int height, const std::string& name) {
  const char* folder = std::getenv("RFBSIM_TEST_ARTIFACTS");
  if (folder == nullptr) return;
  std::ofstream out(std::string(folder) + "/" + name + ".ppm", std::ios::binary);
  out << "P6\n" << width << " " << height << "\n255\n";
  for (std::size_t i = 0; i + 3 < pixels.size(); i += 4) out.write(reinterpret_cast<const char*>(&pixels[i]), 3);
}

// Lets the client take whatever updates arrive for `duration`.
void pump_for(RfbTestClient& client, std::chrono::milliseconds duration) {
  client.pump_until([] { return false; }, duration);
}

}  // namespace

TEST_CASE("mujoco_rfb shows the arm, holds still without keys, W moves the arm, the pointer moves the camera",
          "[waits]") {
  // Any folder makes the server answer HTTP too, and its ready line an http:// URL.
  ScratchDir page("mujoco_rfb_page");
  page.write("index.html", "<!DOCTYPE html><title>mujoco_rfb test</title>\n");
  SimProcess sim(MUJOCO_RFB_BINARY, {"--port", "0", "--web-root", page.path().string()});
  RfbTestClient client("127.0.0.1", sim.port());
  REQUIRE(client.width() == 640);
  REQUIRE(client.height() == 480);
  REQUIRE(client.wait_for_updates(1, 10s));

  // The first picture is MuJoCo's scene: many colours and a real range of brightness, not a flat fill.
  pump_for(client, 1500ms);  // the arm settles onto its servos' targets
  const std::vector<std::uint8_t> first = copy_of(client.frame());
  keep_picture(first, client.width(), client.height(), "mujoco_rfb_first");
  const auto [colours, luma_range] = variety(first);
  INFO("colours " << colours << ", luma range " << luma_range);
  CHECK(colours > 50);
  CHECK(luma_range > 64);

  // With no key, nothing moves: the picture a second later is the same one.
  pump_for(client, 1000ms);
  const std::vector<std::uint8_t> still = copy_of(client.frame());
  const double drift = changed_fraction(first, still);
  INFO("changed without a key: " << drift);
  CHECK(drift < 0.001);

  // Holding W moves the shoulder's target: the arm leans over and the picture changes.
  client.send_key('w', true);
  pump_for(client, 700ms);
  client.send_key('w', false);
  double moved = 0;
  client.pump_until([&] {
    moved = changed_fraction(still, copy_of(client.frame()));
    return moved > 0.01;
  }, 5s);
  keep_picture(copy_of(client.frame()), client.width(), client.height(), "mujoco_rfb_after_w");
  INFO("changed after W: " << moved);
  CHECK(moved > 0.01);

  // The pointer moves the camera: a wheel click zooms, a left drag orbits.
  const auto changes_after = [&](const std::vector<std::uint8_t>& before) {
    double changed = 0;
    client.pump_until([&] {
      changed = changed_fraction(before, copy_of(client.frame()));
      return changed > 0.05;
    }, 5s);
    return changed;
  };
  pump_for(client, 1000ms);  // the arm comes to rest again
  const std::vector<std::uint8_t> before_zoom = copy_of(client.frame());
  client.send_pointer(320, 240, 8);  // wheel up: press and release of button 4
  client.send_pointer(320, 240, 0);
  const double zoomed = changes_after(before_zoom);
  INFO("changed after a wheel click: " << zoomed);
  CHECK(zoomed > 0.05);
  const std::vector<std::uint8_t> before_drag = copy_of(client.frame());
  client.send_pointer(300, 240, 1);
  client.send_pointer(380, 240, 1);
  client.send_pointer(380, 240, 0);
  const double orbited = changes_after(before_drag);
  keep_picture(copy_of(client.frame()), client.width(), client.height(), "mujoco_rfb_after_drag");
  INFO("changed after a left drag: " << orbited);
  CHECK(orbited > 0.05);

  // SIGTERM ends it cleanly.
  const int status = sim.stop(SIGTERM);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
}

TEST_CASE("mujoco_rfb refuses bad flags with status 2 and a model it cannot load with status 1") {
  const auto bad_flag = rfbsim::test::run_to_exit(MUJOCO_RFB_BINARY, {"--port", "http"});
  REQUIRE(WIFEXITED(bad_flag.status));
  CHECK(WEXITSTATUS(bad_flag.status) == 2);
  CHECK_THAT(bad_flag.output, Catch::Contains("bad value 'http' for --port"));

  const auto unknown = rfbsim::test::run_to_exit(MUJOCO_RFB_BINARY, {"--scenario", "lab"});
  REQUIRE(WIFEXITED(unknown.status));
  CHECK(WEXITSTATUS(unknown.status) == 2);
  CHECK_THAT(unknown.output, Catch::Contains("unknown argument '--scenario'"));

  const auto loud = rfbsim::test::run_to_exit(MUJOCO_RFB_BINARY, {"--log-level", "loud"});
  REQUIRE(WIFEXITED(loud.status));
  CHECK(WEXITSTATUS(loud.status) == 2);
  CHECK_THAT(loud.output, Catch::Contains("bad value 'loud' for --log-level (expected error, warn, info or debug)"));

  ScratchDir dir("mujoco_rfb_model");
  const std::string broken = dir.write("broken.xml", "<mujoco><worldbody><geom type='nonsense'/></worldbody>");
  // --log-level debug is taken: the model is what fails.
  const auto bad_model =
      rfbsim::test::run_to_exit(MUJOCO_RFB_BINARY, {"--port", "0", "--log-level", "debug", "--model", broken});
  REQUIRE(WIFEXITED(bad_model.status));
  CHECK(WEXITSTATUS(bad_model.status) == 1);
  CHECK_THAT(bad_model.output, Catch::Contains("cannot load the model '" + broken + "'"));
}
