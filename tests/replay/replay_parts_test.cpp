// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay's pure parts on tiny inputs with exact results: the command line, the provenance check, the
// line-by-line trajectory comparison, the progress line, and the scene builder's top view.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "file_text.hpp"
#include "progress_line.hpp"
#include "replay/provenance.hpp"
#include "render/scene_builder.hpp"
#include "replay_cli.hpp"
#include "trajectory_diff.hpp"

using namespace rfbsim;
using rfbsim::test::write_text;
using namespace rfbsim::replay;

namespace {

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("rfbsim_replay_parts_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

constexpr const char* kHeader = "tick,time,kind,id,x,y,yaw,vx,vy\n";
constexpr const char* kRow0 = "0,0.000000,avatar,0,1.000000,2.000000,0.000000,0.000000,0.000000\n";
constexpr const char* kRow6 = "6,0.100000,avatar,0,1.100000,2.000000,0.000000,1.000000,0.000000\n";

}  // namespace

TEST_CASE("the command line takes a session folder, the video and its view, the output folder and force") {
  CliError error;
  const auto full = parse_cli({"s", "--video", "out.mp4", "--view=top", "--out-dir", "o", "--force", "-q"}, error);
  REQUIRE(full);
  CHECK(full->session_dir == "s");
  CHECK(full->video == std::filesystem::path("out.mp4"));
  CHECK(full->view == View::Top);
  CHECK(full->out_dir == std::filesystem::path("o"));
  CHECK(full->force);
  CHECK(full->quiet);
  const auto check = parse_cli({"--check-only", "s"}, error);
  REQUIRE(check);
  CHECK_FALSE(check->video);
  CHECK(check->view == View::Participant);

  const auto fails = [](std::vector<std::string> args) {
    CliError e;
    return parse_cli(args, e) ? std::string() : e.message;
  };
  CHECK(fails({}) == "SESSION_DIR is missing");
  CHECK(fails({"a", "b"}) == "expected one SESSION_DIR");
  CHECK(fails({"s", "--video"}) == "--video needs a value");
  CHECK(fails({"s", "--view", "side", "--video", "v.mp4"}) == "bad value 'side' for --view (expected participant or top)");
  CHECK(fails({"s", "--view", "top"}) == "--view chooses the video's camera: it needs --video FILE");
  CHECK(fails({"s", "--check-only", "--video", "v.mp4"}) ==
        "--check-only writes no video: give --video or --check-only, not both");
  CHECK(fails({"s", "--speed", "2"}) == "unknown argument '--speed'");
  CHECK(parse_cli({"--", "-odd-folder"}, error)->session_dir == "-odd-folder");
}

TEST_CASE("the command line takes the log's level names for --log-level, info by default") {
  CliError error;
  CHECK(parse_cli({"s"}, error)->log_level == "info");
  const auto debug = parse_cli({"s", "--log-level", "debug"}, error);
  REQUIRE(debug);
  CHECK(debug->log_level == "debug");
  CHECK_FALSE(parse_cli({"s", "--log-level", "loud"}, error));
  CHECK(error.message == "bad value 'loud' for --log-level (expected error, warn, info or debug)");
}

TEST_CASE("provenance names each versions field that differs from this build and these files") {
  sim::SessionMeta meta;
  meta.rfbsim_version = "0.1.0";
  meta.build = "GNU 12.2.0 RelWithDebInfo";
  meta.scenario_sha256 = "aa";
  meta.map_sha256 = "bb";
  CHECK(build_mismatches(meta, "0.1.0", "GNU 12.2.0 RelWithDebInfo").empty());
  const auto builds = build_mismatches(meta, "0.2.0", "GNU 12.2.0 Debug");
  REQUIRE(builds.size() == 2);
  CHECK(builds[0].field == "versions.rfbsim");
  CHECK(describe(builds[1]) ==
        "versions.build differs: recorded 'GNU 12.2.0 RelWithDebInfo', this build 'GNU 12.2.0 Debug' (recorded by another "
        "build (compiler or build type): floating point may round differently)");

  sim::SessionInfo now;
  now.scenario_file = "/s/lab.yaml";
  now.scenario_sha256 = "aa";
  now.map_sha256 = "cc";
  const auto files = file_mismatches(meta, now);
  REQUIRE(files.size() == 1);
  CHECK(describe(files[0]) ==
        "versions.map_sha256 differs: recorded 'bb', now 'cc' (the map image of /s/lab.yaml changed since the recording)");
}

TEST_CASE("trajectories are compared line by line, naming the first line and the columns that differ") {
  const auto recorded = scratch("recorded.csv");
  const auto replayed = scratch("replayed.csv");
  write_text(recorded, std::string(kHeader) + kRow0 + kRow6);
  write_text(replayed, std::string(kHeader) + kRow0 + kRow6);
  TrajectoryComparison same = compare_trajectories(recorded, replayed, false);
  CHECK_FALSE(same.difference);
  CHECK(same.rows == 2);

  // One number changed on line 3.
  write_text(replayed, std::string(kHeader) + kRow0 + "6,0.100000,avatar,0,1.100001,2.000000,0.000000,1.000000,0.000000\n");
  const TrajectoryComparison changed = compare_trajectories(recorded, replayed, false);
  REQUIRE(changed.difference);
  CHECK(changed.rows == 1);
  CHECK(changed.difference->line == 3);
  CHECK(changed.difference->columns == std::vector<std::string>{"x"});
  CHECK(describe(*changed.difference) ==
        "trajectories.csv line 3 (tick 6, avatar 0, column x):\n"
        "  recorded: 6,0.100000,avatar,0,1.100000,2.000000,0.000000,1.000000,0.000000\n"
        "  replayed: 6,0.100000,avatar,0,1.100001,2.000000,0.000000,1.000000,0.000000");

  // A log cut short by a crash (a torn last line) matches what it has; a clean log must have every row.
  write_text(replayed, std::string(kHeader) + kRow0 + kRow6);
  write_text(recorded, std::string(kHeader) + kRow0 + "6,0.1000");
  const TrajectoryComparison crashed = compare_trajectories(recorded, replayed, true);
  CHECK_FALSE(crashed.difference);
  CHECK(crashed.rows == 1);
  const TrajectoryComparison short_log = compare_trajectories(recorded, replayed, false);
  REQUIRE(short_log.difference);
  CHECK(short_log.difference->line == 3);
  CHECK(short_log.difference->recorded == "(end of file)");

  // A replay that stops early is always a difference.
  write_text(recorded, std::string(kHeader) + kRow0 + kRow6);
  write_text(replayed, std::string(kHeader) + kRow0);
  const TrajectoryComparison stopped = compare_trajectories(recorded, replayed, true);
  REQUIRE(stopped.difference);
  CHECK(stopped.difference->replayed == "(end of file)");
}

TEST_CASE("the progress line is quiet at first, then redraws on a terminal or writes a line per tenth to a log") {
  ProgressLine terminal(100.0, true, 2.0);
  CHECK(terminal.step(5.0, 1.0).empty());
  CHECK(terminal.step(20.0, 2.5) == "\rsim_replay: 20.0 / 100.0 s simulated (20 %), 8.0x real time   ");
  CHECK(terminal.step(21.0, 2.6).empty());  // redrawn at most four times a second
  CHECK(terminal.finish() == "\n");
  ProgressLine log(100.0, false, 0.0);
  CHECK(log.step(5.0, 1.0) == "5.0 / 100.0 s simulated (5 %), 5.0x real time");
  CHECK(log.step(9.0, 2.0).empty());
  CHECK_FALSE(log.step(10.0, 2.0).empty());
  CHECK(log.finish().empty());
  CHECK(ProgressLine(100.0, true).finish().empty());
}

TEST_CASE("the top view looks straight down on the whole map, fitted to the frame, and marks the avatar") {
  // A 10 x 6 m room whose origin is not the world's.
  sim::World world;
  std::vector<std::string> rows(12, std::string(20, '.'));
  rows.front() = rows.back() = std::string(20, '#');
  world.map = sim::grid_from_text({rows[0], rows[1], rows[2], rows[3], rows[4], rows[5], rows[6], rows[7], rows[8],
                                   rows[9], rows[10], rows[11]},
                                  0.5);
  world.map.origin_x = 2.0;
  world.map.origin_y = -1.0;
  world.avatar.pose = {4.0, 1.0, 0.5};

  const sim::Scene participant = sim::build_scene(world);
  for (const float aspect : {16.0f / 9.0f, 4.0f / 3.0f, 0.5f}) {
    sim::SceneStyle style;
    style.top_view = true;
    style.top_view_aspect = aspect;
    const sim::Scene top = sim::build_scene(world, style);

    // The same things as the participant sees, plus one translucent disc at the avatar's feet.
    REQUIRE(top.items.size() == participant.items.size() + 1);
    for (std::size_t i = 0; i < participant.items.size(); ++i) {
      CHECK(top.items[i].model.matrix() == participant.items[i].model.matrix());
    }
    const sim::DrawItem& ring = top.items.back();
    CHECK(ring.shape == sim::Shape::Disc);
    CHECK(ring.opacity < 1.0f);
    CHECK(ring.model.translation().x() == Approx(4.0));
    CHECK(ring.model.translation().y() == Approx(1.0));

    // Above the centre of the map (x 2..12, y -1..5), looking down, no fog.
    const Eigen::Vector3f eye = top.camera.eye;
    CHECK(top.camera.target.x() == Approx(7.0));
    CHECK(top.camera.target.y() == Approx(2.0));
    CHECK(eye.x() == Approx(7.0));
    CHECK(eye.y() == Approx(2.0).margin(0.05));
    const Eigen::Vector3f forward = (top.camera.target - eye).normalized();
    CHECK(forward.z() < -0.999f);
    CHECK(top.fog_start > 1000.0f);

    // The renderer's projection (gl_renderer.cpp: look_at with z up, then perspective): every corner of the map,
    // on the floor and at the wall tops, lands inside the picture, and the tighter side nearly fills it.
    const Eigen::Vector3f side = forward.cross(Eigen::Vector3f::UnitZ()).normalized();
    const Eigen::Vector3f up = side.cross(forward);
    const float half_fov = top.camera.fov_y_degrees * std::numbers::pi_v<float> / 360.0f;
    const auto project = [&](float x, float y, float z) {
      const Eigen::Vector3f d = Eigen::Vector3f(x, y, z) - eye;
      const float depth = d.dot(forward);
      return Eigen::Vector2f(d.dot(side) / (depth * std::tan(half_fov) * aspect), d.dot(up) / (depth * std::tan(half_fov)));
    };
    float widest = 0.0f;
    for (const float z : {0.0f, 2.2f}) {
      for (const float x : {2.0f, 12.0f}) {
        for (const float y : {-1.0f, 5.0f}) {
          const Eigen::Vector2f at = project(x, y, z);
          CHECK(std::abs(at.x()) <= 1.0f);
          CHECK(std::abs(at.y()) <= 1.0f);
          widest = std::max({widest, std::abs(at.x()), std::abs(at.y())});
        }
      }
    }
    CHECK(widest > 0.9f);
    // North is up and east is right in the picture.
    CHECK(project(7.0f, 4.0f, 0.0f).y() > 0.0f);
    CHECK(project(10.0f, 2.0f, 0.0f).x() > 0.0f);
  }
}
