// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay --video: an H.264 MP4 at the recorded frame size and rate with one frame per 1/fps of the
// session, read back by ffprobe and decoded by ffmpeg; the top view shows another picture than the
// participant's, and a first-person session is filmed from its own camera; a video of a replay that departs from
// the log, or one that cannot be written, is not left.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "file_text.hpp"
#include "replay_fixtures.hpp"
#include "sim_process.hpp"
#include "skip.hpp"

using namespace rfbsim;
using rfbsim::test::contains;
using nlohmann::json;

namespace {

// The lab at 320x240, a viewer from the start, walking and turning, ended by a signal at tick 300.
test::Recording record_small_lab(const std::filesystem::path& dir) {
  test::RecordSpec spec;
  spec.max_ticks = 300;
  spec.script = [](sim::StudySession& study, std::uint64_t tick) {
    if (tick == 5) study.key('w', true, 1);
    if (tick == 120) study.key('a', true, 1);
    if (tick == 160) study.key('a', false, 1);
  };
  return record_session(spec, dir);
}

// ffprobe's view of the first video stream, frames counted by decoding (-count_frames).
json probe(const std::filesystem::path& video) {
  const test::ExitResult result =
      test::run_to_exit(RFBSIM_FFPROBE, {"-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                                         "stream=codec_name,width,height,r_frame_rate,pix_fmt,nb_read_frames", "-of", "json",
                                         video.string()},
                        std::chrono::seconds(60));
  INFO(result.output);
  REQUIRE(WIFEXITED(result.status));
  REQUIRE(WEXITSTATUS(result.status) == 0);
  const json doc = json::parse(result.output);
  REQUIRE(doc["streams"].size() == 1);
  return doc["streams"][0];
}

// Frame `index` of `video` decoded by ffmpeg into RGB bytes.
std::string decoded_frame(const std::filesystem::path& video, int index, const std::filesystem::path& raw) {
  const test::ExitResult result = test::run_to_exit(
      RFBSIM_FFMPEG, {"-v", "error", "-y", "-i", video.string(), "-vf", "select=eq(n\\," + std::to_string(index) + ")",
                      "-frames:v", "1", "-f", "rawvideo", "-pix_fmt", "rgb24", raw.string()},
      std::chrono::seconds(60));
  INFO(result.output);
  REQUIRE(WIFEXITED(result.status));
  REQUIRE(WEXITSTATUS(result.status) == 0);
  std::ifstream in(raw, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

double mean_abs_difference(const std::string& a, const std::string& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sum += std::abs(static_cast<double>(static_cast<unsigned char>(a[i])) - static_cast<unsigned char>(b[i]));
  }
  return sum / static_cast<double>(a.size());
}

// How much a picture varies: the mean distance of its bytes from their mean (a blank frame has none).
double spread(const std::string& bytes) {
  double mean = 0.0;
  for (const char c : bytes) mean += static_cast<unsigned char>(c);
  mean /= static_cast<double>(bytes.size());
  double sum = 0.0;
  for (const char c : bytes) sum += std::abs(static_cast<unsigned char>(c) - mean);
  return sum / static_cast<double>(bytes.size());
}

bool have_ffmpeg() { return !std::string(RFBSIM_FFPROBE).empty() && !std::string(RFBSIM_FFMPEG).empty(); }

}  // namespace

TEST_CASE("the video is H.264 at the recorded size and rate with one frame per two ticks, in both views") {
  if (!have_ffmpeg()) RFBSIM_SKIP("ffprobe or ffmpeg not found at configure time (apt-get install ffmpeg)");
  const auto dir = test::fresh_dir("video");
  const test::Recording recording = record_small_lab(dir);
  REQUIRE(recording.end_tick == 300);
  const auto participant = dir.parent_path() / "participant.mp4";
  const auto top = dir.parent_path() / "top.mp4";

  for (const auto& [view, video] : {std::pair{"participant", participant}, std::pair{"top", top}}) {
    const test::ReplayRun run = test::run_replay({dir.string(), "--video", video.string(), "--view", view});
    INFO(run.output);
    REQUIRE(run.exit_code == 0);
    CHECK(contains(run.output, "poses match the log"));
    CHECK(contains(run.output, "150 frames at 30 fps, 320x240"));
    CHECK_FALSE(std::filesystem::exists(video.string() + ".partial"));

    const json stream = probe(video);
    CHECK(stream["codec_name"] == "h264");
    CHECK(stream["width"] == 320);
    CHECK(stream["height"] == 240);
    CHECK(stream["pix_fmt"] == "yuv420p");
    CHECK(stream["r_frame_rate"] == "30/1");
    // One frame per 1/30 s of a 60 Hz session: end_tick / 2, exactly (frame k shows tick 2k, k < 150).
    CHECK(stream["nb_read_frames"] == std::to_string(recording.end_tick / 2));
  }

  // The same moment from the two cameras: two real pictures, and different ones.
  const std::string a = decoded_frame(participant, 120, dir.parent_path() / "participant.rgb");
  const std::string b = decoded_frame(top, 120, dir.parent_path() / "top.rgb");
  REQUIRE(a.size() == 320u * 240u * 3u);
  REQUIRE(b.size() == a.size());
  CHECK(spread(a) > 10.0);
  CHECK(spread(b) > 10.0);
  CHECK(mean_abs_difference(a, b) > 15.0);
  // And the participant's picture changes as the avatar walks: the first and a late frame differ.
  CHECK(mean_abs_difference(a, decoded_frame(participant, 0, dir.parent_path() / "first.rgb")) > 5.0);
}

TEST_CASE("no video is left when the replay departs from the log or the file cannot be written") {
  const auto dir = test::fresh_dir("video_refused");
  record_small_lab(dir);

  SECTION("a replay that departs from the log") {
    auto lines = test::read_lines(dir / "trajectories.csv");
    REQUIRE(lines.size() > 60);
    lines[60].back() = lines[60].back() == '1' ? '2' : '1';  // the last digit of vy
    test::write_lines(dir / "trajectories.csv", lines);
    const auto video = dir.parent_path() / "departed.mp4";
    const test::ReplayRun run = test::run_replay({dir.string(), "--video", video.string()});
    INFO(run.output);
    CHECK(run.exit_code == 3);
    CHECK(contains(run.output, "line 61"));
    CHECK(contains(run.output, "no video written"));
    CHECK_FALSE(std::filesystem::exists(video));
    CHECK_FALSE(std::filesystem::exists(video.string() + ".partial"));
  }
  SECTION("a file in a folder that does not exist") {
    const auto video = dir.parent_path() / "no_such_folder" / "out.mp4";
    const test::ReplayRun run = test::run_replay({dir.string(), "--video", video.string()});
    INFO(run.output);
    CHECK(run.exit_code == 1);
    CHECK(contains(run.output, "video: " + video.string() + ": cannot open for writing (No such file or directory)"));
  }
}

TEST_CASE("the participant video of a first-person session is filmed from the camera session.json names") {
  if (!have_ffmpeg()) RFBSIM_SKIP("ffprobe or ffmpeg not found at configure time (apt-get install ffmpeg)");
  const auto dir = test::fresh_dir("video_first_person");
  test::RecordSpec spec;
  spec.parameters = {{"camera", "first_person"}};
  spec.max_ticks = 60;
  (void)test::record_session(spec, dir);
  // The same session with the key saying third_person: the world replays the same (the parameters are
  // unchanged), and only the film's camera follows the key.
  const auto third = test::copy_session(dir, "video_first_person_as_third");
  json session = json::parse(std::ifstream(third / "session.json"));
  REQUIRE(session["camera"] == "first_person");
  session["camera"] = "third_person";
  std::ofstream(third / "session.json") << session.dump(2) << "\n";

  std::vector<std::string> frames;
  for (const auto& [folder, name] : {std::pair{dir, "fp"}, std::pair{third, "tp"}}) {
    const auto video = dir.parent_path() / (std::string(name) + ".mp4");
    const test::ReplayRun run = test::run_replay({folder.string(), "--video", video.string()});
    INFO(run.output);
    REQUIRE(run.exit_code == 0);
    frames.push_back(decoded_frame(video, 20, dir.parent_path() / (std::string(name) + ".rgb")));
  }
  REQUIRE(frames[0].size() == 320u * 240u * 3u);
  REQUIRE(frames[1].size() == frames[0].size());
  CHECK(spread(frames[0]) > 10.0);
  CHECK(mean_abs_difference(frames[0], frames[1]) > 5.0);
}
