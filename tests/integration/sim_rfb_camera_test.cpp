// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb --camera as a real process: the test room (a still world: no people, no robot) served with
// first_person and with third_person at the same seed gives two different pictures, and only the third-person
// one shows the avatar's blue shirt in front of the camera.
#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "eventually.hpp"
#include "rfb_test_client.hpp"
#include "sim_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::RfbTestClient;
using rfbsim::test::SimProcess;

namespace {

constexpr int kCameraTestWidth = 320, kCameraTestHeight = 240;

// RGBA, top row first.
std::vector<std::uint8_t> copy_of(const rfbsim::FrameView& frame) {
  std::vector<std::uint8_t> pixels;
  for (int y = 0; y < frame.height; ++y) pixels.insert(pixels.end(), frame.row(y), frame.row(y) + frame.width * 4);
  return pixels;
}

// The picture a viewer of sim_rfb started with `--camera camera` settles on. The world is still, so the frame
// stops changing once its tiles have all arrived: two equal looks, a moment apart, that are not all black.
std::vector<std::uint8_t> served_picture(const std::string& camera) {
  SimProcess sim(rfbsim::test::sim_rfb_path(), {"--port", "0", "--width", std::to_string(kCameraTestWidth),
                                                "--height", std::to_string(kCameraTestHeight), "--seed", "5",
                                                "--camera", camera});
  RfbTestClient client("127.0.0.1", sim.port());
  REQUIRE(client.width() == kCameraTestWidth);
  REQUIRE(client.wait_for_updates(1, 10s));
  std::vector<std::uint8_t> last = copy_of(client.frame());
  const bool settled = rfbsim::test::eventually(
      [&] {
        client.pump_until([] { return false; }, 300ms);
        std::vector<std::uint8_t> now = copy_of(client.frame());
        const bool same = now == last;
        last = std::move(now);
        return same && std::any_of(last.begin(), last.end(), [](std::uint8_t v) { return v > 0; });
      },
      20s);
  REQUIRE(settled);
  return last;
}

// Whether the centre column, in the lower middle of the frame, shows the avatar's shirt (0x2f7fd0, lit): blue
// well above red, which neither the walls, the floor nor the sky are.
bool shirt_at_centre(const std::vector<std::uint8_t>& pixels) {
  for (int y = 100; y < 200; ++y) {
    const std::uint8_t* p = pixels.data() + (static_cast<std::size_t>(y) * kCameraTestWidth + kCameraTestWidth / 2) * 4;
    if (p[2] > p[0] + 60) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("sim_rfb --camera first_person serves a different picture from third_person, without the avatar") {
  const std::vector<std::uint8_t> third = served_picture("third_person");
  const std::vector<std::uint8_t> first = served_picture("first_person");
  const rfbsim::FrameView a{third.data(), kCameraTestWidth, kCameraTestHeight, 0};
  const rfbsim::FrameView b{first.data(), kCameraTestWidth, kCameraTestHeight, 0};
  CHECK(rfbsim::test::mean_abs_difference(a, b) > 5.0);
  CHECK(shirt_at_centre(third));
  CHECK_FALSE(shirt_at_centre(first));
}

TEST_CASE("sim_rfb refuses a --camera that is neither view, naming the choices") {
  const auto result = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--camera", "overhead"});
  CHECK(WIFEXITED(result.status));
  CHECK(WEXITSTATUS(result.status) != 0);
  CHECK(result.output.find("bad value 'overhead' for --camera (expected third_person or first_person)") !=
        std::string::npos);
}
