// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay shows the view the participant had: session.json's `camera` (first_person from a link or the
// command line) chooses the video's camera, and a session.json from before the key is third person.
#include <catch2/catch.hpp>

#include <fstream>
#include <nlohmann/json.hpp>

#include "record/session_log.hpp"
#include "replay_fixtures.hpp"
#include "replay_job.hpp"
#include "replay/session_replay.hpp"

using namespace rfbsim;
using nlohmann::json;

TEST_CASE("a first-person session replays, and its video is drawn from the participant's eyes") {
  const auto dir = test::fresh_dir("first_person");
  test::RecordSpec spec;
  spec.parameters = {{"camera", "first_person"}};
  spec.max_ticks = 60;
  spec.script = [](sim::StudySession& session, std::uint64_t tick) {
    if (tick == 5) session.key('w', true, 1);  // walk, so that the poses say something
  };
  (void)test::record_session(spec, dir);

  const sim::SessionMeta meta = sim::read_session(dir).meta;
  CHECK(meta.camera == sim::CameraMode::kFirstPerson);
  const sim::SceneStyle participant = replay::video_style(replay::View::Participant, meta);
  CHECK(participant.camera == sim::CameraMode::kFirstPerson);
  CHECK_FALSE(participant.top_view);
  CHECK(replay::video_style(replay::View::Top, meta).top_view);

  // The replay itself matches, and records the same view again.
  const auto out = test::fresh_dir("first_person_replay");
  const test::ReplayRun run = test::run_replay({dir.string(), "--out-dir", out.string()});
  INFO(run.output);
  CHECK(run.exit_code == 0);
  CHECK(sim::read_session(out).meta.camera == sim::CameraMode::kFirstPerson);
}

TEST_CASE("a session.json without camera (recorded before the key) is replayed in the third person") {
  const auto dir = test::fresh_dir("no_camera_key");
  test::RecordSpec spec;
  spec.max_ticks = 30;
  (void)test::record_session(spec, dir);
  json session = json::parse(std::ifstream(dir / "session.json"));
  CHECK(session["camera"] == "third_person");
  session.erase("camera");
  std::ofstream(dir / "session.json") << session.dump(2) << "\n";

  const sim::SessionMeta meta = sim::read_session(dir).meta;
  CHECK(meta.camera == sim::CameraMode::kThirdPerson);
  CHECK(replay::video_style(replay::View::Participant, meta).camera == sim::CameraMode::kThirdPerson);

  // A value that is neither is an error naming the key, as for every other key.
  session["camera"] = "overhead";
  std::ofstream(dir / "session.json") << session.dump(2) << "\n";
  try {
    (void)sim::read_session(dir);
    FAIL("no error for camera overhead");
  } catch (const sim::SessionLogError& e) {
    CHECK_THAT(e.what(), Catch::Contains("camera"));
  }
}
