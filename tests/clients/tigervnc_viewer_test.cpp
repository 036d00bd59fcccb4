// SPDX-License-Identifier: GPL-2.0-or-later
// TigerVNC's viewer (xtigervncviewer) on sim_rfb's raw RFB port, in an Xvfb display of its own: its window shows the
// scene, W held in it walks the avatar, its stream is Tight with ContinuousUpdates and Fence, and its
// -QualityLevel and -CompressLevel reach the server as a cap on this client's JPEG quality.
#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "eventually.hpp"
#include "rfb_test_client.hpp"
#include "scratch_dir.hpp"
#include "sim_process.hpp"
#include "xwd_image.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ChildProcess;
using rfbsim::test::ChildSpec;
using rfbsim::test::eventually;
using rfbsim::test::http_body;
using rfbsim::test::http_get;
using rfbsim::test::json_number;
using rfbsim::test::SimProcess;
using rfbsim::test::XwdImage;

namespace {

// Generous: a loaded CI machine starts Xvfb, a simulator and a viewer side by side. They bound a hang; they
// measure nothing.
constexpr auto kStartLimit = 60s;
constexpr auto kLimit = 30s;
constexpr int kWidth = 320;
constexpr int kHeight = 240;

// Where the logs and the last screenshot of each test are kept (artifacts/clients in the build folder).
std::string artifact(const std::string& name) {
  std::filesystem::create_directories(RFBSIM_CLIENTS_ARTIFACTS);
  return (std::filesystem::path(RFBSIM_CLIENTS_ARTIFACTS) / name).string();
}

// A virtual X display of our own: Xvfb picks a free number and writes it to a pipe (-displayfd), so tests that
// run side by side never collide.
class VirtualDisplay {
 public:
  explicit VirtualDisplay(const std::string& log) {
    int ready[2];
    REQUIRE(::pipe2(ready, O_CLOEXEC) == 0);
    server_ = std::make_unique<ChildProcess>(ChildSpec{
        {RFBSIM_XVFB, "-displayfd", std::to_string(ready[1]), "-screen", "0", "800x600x24", "-nolisten", "tcp"},
        {},
        log,
        ready[1]});
    ::close(ready[1]);
    std::string text;
    const auto deadline = std::chrono::steady_clock::now() + kStartLimit;
    while (text.find('\n') == std::string::npos && std::chrono::steady_clock::now() < deadline) {
      pollfd pfd{ready[0], POLLIN, 0};
      if (::poll(&pfd, 1, 200) <= 0) continue;
      char buffer[32];
      const auto n = ::read(ready[0], buffer, sizeof buffer);
      if (n <= 0) break;
      text.append(buffer, static_cast<std::size_t>(n));
    }
    ::close(ready[0]);
    INFO("Xvfb's log: " << log);
    REQUIRE(text.find('\n') != std::string::npos);
    name_ = ":" + text.substr(0, text.find('\n'));
  }

  [[nodiscard]] std::string env() const { return "DISPLAY=" + name_; }

 private:
  std::unique_ptr<ChildProcess> server_;
  std::string name_;
};

std::string status_of(const SimProcess& sim) { return http_body(http_get(sim.port(), "/status.json")); }

// The "streams" array of a status document ("" when it has none).
std::string streams_of(const std::string& status) {
  const auto at = status.find("\"streams\":[");
  if (at == std::string::npos) return "";
  const auto end = status.find(']', at);
  return end == std::string::npos ? "" : status.substr(at + 10, end - at - 9);
}

// Polls /status.json until `done(status)` holds or `limit` passes; `status` keeps the last one read.
template <typename Done>
bool await_status(const SimProcess& sim, Done done, std::string& status, std::chrono::milliseconds limit = kLimit) {
  return eventually([&] {
    status = status_of(sim);
    return done(status);
  }, limit, 100ms);
}

// One run of xdotool (or any short X program) in `display`: its output, nullopt if it failed.
std::optional<std::string> x_tool(const VirtualDisplay& display, const std::vector<std::string>& argv) {
  int status = 0;
  std::string output = rfbsim::test::run_child({argv, {display.env()}, "", -1}, status);
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return std::nullopt;
  return output;
}

// TigerVNC's viewer connected to `port`, with `options` before the server's address.
class Viewer {
 public:
  Viewer(const VirtualDisplay& display, const rfbsim::test::ScratchDir& home, int port,
         const std::vector<std::string>& options, const std::string& log) {
    // No dialog to wait on a person: a failure ends the viewer, and it does not try again by itself.
    std::vector<std::string> argv{RFBSIM_XTIGERVNCVIEWER, "-AlertOnFatalError=0", "-ReconnectOnError=0"};
    argv.insert(argv.end(), options.begin(), options.end());
    argv.push_back("127.0.0.1::" + std::to_string(port));
    // A HOME of its own: the viewer keeps a history and settings under ~/.vnc.
    process_ = std::make_unique<ChildProcess>(ChildSpec{argv, {display.env(), "HOME=" + home.path().string()}, log, -1});
  }
  [[nodiscard]] bool running() { return process_->running(); }

 private:
  std::unique_ptr<ChildProcess> process_;
};

// The viewer's window: its title is "<desktop name> - TigerVNC", and sim_rfb's desktop is "rfbsim".
std::string viewer_window(const VirtualDisplay& display) {
  std::string window;
  eventually([&] {
    const std::string found =
        x_tool(display, {RFBSIM_XDOTOOL, "search", "--name", "^rfbsim - TigerVNC$"}).value_or("");
    window = found.substr(0, found.find('\n'));
    return !window.empty();
  }, kLimit, 200ms);
  return window;
}

// A screenshot of `window` (xwd), also saved as `keep` in the artifacts; nullopt if xwd failed.
std::optional<XwdImage> screenshot(const VirtualDisplay& display, const std::string& window, const std::string& keep) {
  const std::string bytes = x_tool(display, {RFBSIM_XWD, "-silent", "-id", window}).value_or("");
  std::ofstream(artifact(keep), std::ios::binary) << bytes;
  std::string error;
  auto image = rfbsim::test::parse_xwd(bytes, error);
  if (!image) UNSCOPED_INFO("screenshot: " << error);
  return image;
}

// Whether `image` is the scene as sim_rfb draws it at kWidth x kHeight: the viewer's window holds the whole
// framebuffer, a sky (blue over red) above, and far more colours than a blank or a message would have.
bool shows_scene(const XwdImage& image) {
  if (image.width != kWidth || image.height != kHeight) return false;
  const rfbsim::test::Rgb sky = rfbsim::test::mean_of_rows(image, 0, 10);
  return sky.b > sky.r + 20 && rfbsim::test::distinct_colours(image) > 200;
}

// The picture as RGBA bytes, for comparing with what a libvncclient client receives.
std::vector<std::uint8_t> rgba(const XwdImage& image) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(image.pixels.size() * 4);
  for (const auto& p : image.pixels) bytes.insert(bytes.end(), {p.r, p.g, p.b, 255});
  return bytes;
}

}  // namespace

TEST_CASE("TigerVNC's viewer shows the scene, walks the avatar with W, and streams Tight with fences") {
  rfbsim::test::ScratchDir home("rfbsim_tigervnc");
  const std::string prefix = "tigervnc_walk_";
  VirtualDisplay display(artifact(prefix + "xvfb.log"));
  SimProcess sim(rfbsim::test::sim_rfb_path(),
                 {"--port", "0", "--width", std::to_string(kWidth), "--height", std::to_string(kHeight)}, kStartLimit,
                 artifact(prefix + "sim_rfb.log"));
  Viewer viewer(display, home, sim.port(), {}, artifact(prefix + "viewer.log"));

  // The viewer's stream, as sim_rfb sees it: Tight, pushed (ContinuousUpdates), paced by fences.
  std::string status;
  REQUIRE(await_status(sim, [](const std::string& s) {
    const std::string streams = streams_of(s);
    return json_number(streams, "updates_sent") >= 1 && streams.find("\"continuous_updates\":true") != std::string::npos;
  }, status, kStartLimit));
  std::string streams = streams_of(status);
  INFO(streams);
  CHECK(json_number(status, "clients") == 1);
  CHECK_THAT(streams, Catch::Contains(R"("encoding":"tight")"));
  CHECK_THAT(streams, Catch::Contains(R"("fence":true)"));
  REQUIRE(await_status(sim, [](const std::string& s) { return json_number(streams_of(s), "last_rtt_ms") >= 0; },
                       status));
  // Whatever level the viewer's AutoSelect asked for, the quality in use is at most that and the server's 80.
  streams = streams_of(status);
  const double quality = json_number(streams, "quality");
  CHECK(quality >= 1);
  CHECK(quality <= 80);
  if (json_number(streams, "requested_quality") >= 1) CHECK(quality <= json_number(streams, "requested_quality"));

  // The picture: the viewer's window shows the scene, as a libvncclient client receives it too.
  const std::string window = viewer_window(display);
  REQUIRE(!window.empty());
  std::optional<XwdImage> before;
  REQUIRE(eventually([&] {
    before = screenshot(display, window, prefix + "before.xwd");
    return before && shows_scene(*before);
  }, kLimit, 250ms));
  {
    rfbsim::test::RfbTestClient reference("127.0.0.1", sim.port());
    // Its first picture may still be the grey before the first frame: wait for the sky, as the viewer's.
    REQUIRE(reference.pump_until(
        [&] { return reference.frame().row(5)[2] > reference.frame().row(5)[0] + 20; }, kLimit));
    const std::vector<std::uint8_t> shown = rgba(*before);
    // Both are JPEG of the same still picture: close, not equal.
    CHECK(rfbsim::test::mean_abs_difference(reference.frame(), {shown.data(), kWidth, kHeight, 0}) < 12.0);
  }

  // W held in the viewer's window walks the avatar (sim_rfb's own pose in /status.json), and the picture follows.
  status = status_of(sim);
  const double y0 = json_number(status, "y");
  // Focus, then real key events (XTEST) as a person's keyboard makes them; no window manager runs here.
  REQUIRE(x_tool(display, {RFBSIM_XDOTOOL, "windowfocus", "--sync", window}));
  REQUIRE(x_tool(display, {RFBSIM_XDOTOOL, "keydown", "w"}));
  const bool walked =
      await_status(sim, [&](const std::string& s) { return json_number(s, "y") > y0 + 1.0; }, status);
  x_tool(display, {RFBSIM_XDOTOOL, "keyup", "w"});
  REQUIRE(walked);
  CHECK(std::abs(json_number(status, "x") - 3.5) < 1e-6);  // straight ahead, along +y
  REQUIRE(await_status(sim, [](const std::string& s) { return json_number(s, "speed") == 0.0; }, status));
  // Compared below the middle only: the viewer lays a "Press F8" hint over the upper half for a while after it
  // gains the focus; the floor tiles below slide under the camera as the avatar walks.
  const std::vector<std::uint8_t> first = rgba(*before);
  const auto floor_rows = [](const std::vector<std::uint8_t>& picture) {
    constexpr int kTop = kHeight * 3 / 5;
    return rfbsim::FrameView{picture.data() + std::size_t{kTop} * kWidth * 4, kWidth, kHeight - kTop, 0};
  };
  CHECK(eventually([&] {
    const auto after = screenshot(display, window, prefix + "after.xwd");
    if (!after || !shows_scene(*after)) return false;
    const std::vector<std::uint8_t> now = rgba(*after);
    return rfbsim::test::mean_abs_difference(floor_rows(first), floor_rows(now)) > 5.0;
  }, kLimit, 250ms));
  CHECK(viewer.running());
}

TEST_CASE("TigerVNC's QualityLevel and CompressLevel cap this client's stream") {
  rfbsim::test::ScratchDir home("rfbsim_tigervnc");
  const std::string prefix = "tigervnc_quality_";
  VirtualDisplay display(artifact(prefix + "xvfb.log"));
  SimProcess sim(rfbsim::test::sim_rfb_path(),
                 {"--port", "0", "--width", std::to_string(kWidth), "--height", std::to_string(kHeight)}, kStartLimit,
                 artifact(prefix + "sim_rfb.log"));
  // AutoSelect off: the viewer keeps the level it is given instead of choosing by the measured bandwidth. TigerVNC
  // 1.12 sends its CompressLevel only with CustomCompressLevel on (else it asks for 2).
  Viewer viewer(display, home, sim.port(),
                {"-AutoSelect=0", "-QualityLevel=3", "-CustomCompressLevel=1", "-CompressLevel=1"},
                artifact(prefix + "viewer.log"));

  std::string status;
  REQUIRE(await_status(sim, [](const std::string& s) {
    const std::string streams = streams_of(s);
    return json_number(streams, "updates_sent") >= 1 && json_number(streams, "requested_quality_level") >= 0;
  }, status, kStartLimit));
  const std::string streams = streams_of(status);
  INFO(streams);
  CHECK_THAT(streams, Catch::Contains(R"("encoding":"tight")"));
  // Level 3 is JPEG quality 42 (libvncserver's table, TigerVNC's server's): below the server's 80, so it is this
  // client's top quality.
  CHECK(json_number(streams, "requested_quality_level") == 3);
  CHECK(json_number(streams, "requested_quality") == 42);
  CHECK(json_number(streams, "quality") >= 1);
  CHECK(json_number(streams, "quality") <= 42);
  CHECK(json_number(streams, "compress_level") == 1);

  // At that quality the scene still shows.
  const std::string window = viewer_window(display);
  REQUIRE(!window.empty());
  std::optional<XwdImage> shown;
  CHECK(eventually([&] {
    shown = screenshot(display, window, prefix + "shown.xwd");
    return shown && shows_scene(*shown);
  }, kLimit, 250ms));
  CHECK(viewer.running());
}
