// SPDX-License-Identifier: GPL-2.0-or-later
// TaskMonitor on hand-made worlds: each step's rule, the clock, the outcome and the HUD's words, with exact ticks.
#include <catch2/catch.hpp>

#include <cmath>
#include <utility>

#include "task/task_display.hpp"
#include "task/task_monitor.hpp"

using namespace rfbsim::sim;

namespace {

constexpr double kDt = 1.0 / 60.0;

// A 20 x 20 m open room (0.1 m cells), optionally with a wall across x = 10 m from y = 0 to 20.
World open_room(bool wall = false) {
  World world;
  GridMap map;
  map.width = 200;
  map.height = 200;
  map.resolution = 0.1;
  map.occupied.assign(200 * 200, 0);
  if (wall) {
    for (int row = 0; row < 200; ++row) map.occupied[static_cast<std::size_t>(row * 200 + 100)] = 1;
  }
  world.map = map;
  world.obstacles = map;
  world.avatar.pose = {5.0, 5.0, 0.0};
  world.robot = Robot{};
  world.robot->pose = {8.0, 5.0, 0.0};
  return world;
}

TaskSpec one_step(TaskStep step, double time_limit = 240.0) {
  TaskSpec spec;
  spec.steps.push_back(step);
  spec.time_limit = time_limit;
  return spec;
}

void tick(World& world) {
  ++world.tick;
  world.time = static_cast<double>(world.tick) * kDt;
}

}  // namespace

TEST_CASE("the robot is in view ahead within range, not behind, not too far, not behind a wall") {
  World world = open_room();
  CHECK(robot_in_view(world, 5.0, 0.785));
  world.avatar.pose.yaw = std::acos(-1.0);  // facing away
  CHECK_FALSE(robot_in_view(world, 5.0, 0.785));
  world.avatar.pose.yaw = 0.7;  // 40 degrees off: inside a 45 degree half-angle
  CHECK(robot_in_view(world, 5.0, 0.785));
  world.avatar.pose.yaw = 0.0;
  CHECK_FALSE(robot_in_view(world, 2.9, 0.785));  // 3 m away
  World walled = open_room(true);
  walled.robot->pose = {12.0, 5.0, 0.0};
  CHECK_FALSE(robot_in_view(walled, 10.0, 0.785));
  walled.robot.reset();
  CHECK_FALSE(robot_in_view(walled, 10.0, 0.785));
}

TEST_CASE("nothing happens before the clock starts, and the clock starts once") {
  World world = open_room();
  TaskStep find;
  find.type = TaskType::FindRobot;
  find.distance = 5.0;
  TaskMonitor monitor(one_step(find), kDt);
  tick(world);
  monitor.observe(world);
  CHECK(monitor.events().empty());
  CHECK(monitor.status().step == -1);
  CHECK(monitor.status().time_left == 240.0);
  monitor.start_timer(world);
  monitor.start_timer(world);
  REQUIRE(monitor.events().size() == 2);
  CHECK(monitor.events()[0].kind == TaskEvent::Kind::TimerStarted);
  CHECK(monitor.events()[0].tick == 1);
  CHECK(monitor.events()[1].kind == TaskEvent::Kind::StepStarted);
  CHECK(monitor.events()[1].index == 0);
}

TEST_CASE("finding the robot completes at the first tick it is in view") {
  World world = open_room();
  world.avatar.pose.yaw = std::acos(-1.0);
  TaskStep find;
  find.type = TaskType::FindRobot;
  find.distance = 5.0;
  TaskMonitor monitor(one_step(find), kDt);
  monitor.start_timer(world);
  monitor.clear_events();
  for (int i = 0; i < 10; ++i) {
    tick(world);
    monitor.observe(world);
  }
  CHECK(monitor.outcome() == TaskOutcome::None);
  world.avatar.pose.yaw = 0.0;
  tick(world);
  monitor.observe(world);
  CHECK(monitor.outcome() == TaskOutcome::Completed);
  REQUIRE(monitor.outcome_tick());
  CHECK(*monitor.outcome_tick() == 11);
  REQUIRE(monitor.events().size() == 2);
  CHECK(monitor.events()[0].kind == TaskEvent::Kind::StepDone);
  CHECK(monitor.events()[1].kind == TaskEvent::Kind::Outcome);
  CHECK(monitor.events()[1].outcome == TaskOutcome::Completed);
}

TEST_CASE("following counts only the ticks within range, 30 s in total") {
  World world = open_room();
  TaskStep follow;
  follow.type = TaskType::FollowRobot;
  follow.distance = 2.0;
  follow.duration = 30.0;
  TaskMonitor monitor(one_step(follow), kDt);
  monitor.start_timer(world);
  int observed = 0;
  // 3 m away for 600 ticks (not counted), then 1.5 m away until done: done after 1800 counted ticks.
  while (monitor.outcome() == TaskOutcome::None && observed < 5000) {
    world.robot->pose.x = observed < 600 ? 8.0 : 6.5;
    tick(world);
    monitor.observe(world);
    ++observed;
  }
  CHECK(monitor.outcome() == TaskOutcome::Completed);
  CHECK(observed == 600 + 1800);
}

TEST_CASE("walking, turning and moving the camera add up what changed while the step was current") {
  World world = open_room();
  TaskSpec spec;
  TaskStep walk;
  walk.type = TaskType::Walk;
  walk.distance = 1.0;
  TaskStep turn;
  turn.type = TaskType::Turn;
  turn.angle = 5.0;
  TaskStep camera;
  camera.type = TaskType::Camera;
  camera.distance = 0.5;
  spec.steps = {walk, turn, camera};
  TaskMonitor monitor(spec, kDt);
  monitor.start_timer(world);
  // Turning during the walk step does not count for the turn step.
  for (int i = 0; i < 10; ++i) {
    world.avatar.distance_walked += 0.05;
    world.avatar.pose.yaw += 0.2;
    tick(world);
    monitor.observe(world);
  }
  CHECK(monitor.status().step == 0);
  CHECK(monitor.status().amount == Approx(0.5));
  for (int i = 0; i < 10; ++i) {
    world.avatar.distance_walked += 0.05;
    tick(world);
    monitor.observe(world);
  }
  CHECK(monitor.status().step == 1);
  CHECK(monitor.status().amount == 0.0);
  // Turning left and right both count (total turning), across the +-pi seam too.
  world.avatar.pose.yaw = 3.0;
  tick(world);
  monitor.observe(world);  // the jump from 2.0 + ... is counted: it is the participant's turn
  const double after_jump = monitor.status().amount;
  world.avatar.pose.yaw = -3.0;  // 0.283 rad further across the seam
  tick(world);
  monitor.observe(world);
  CHECK(monitor.status().amount - after_jump == Approx(2.0 * std::acos(-1.0) - 6.0));
  while (monitor.status().step == 1) {
    world.avatar.pose.yaw -= 0.1;
    tick(world);
    monitor.observe(world);
  }
  for (int i = 0; i < 5; ++i) {
    world.camera.height += 0.1;
    tick(world);
    monitor.observe(world);
  }
  CHECK(monitor.outcome() == TaskOutcome::Completed);
}

TEST_CASE("reaching counts within the tolerance of the target, as SEAN-EP's 0.3 m") {
  World world = open_room();
  TaskStep reach;
  reach.type = TaskType::Reach;
  reach.distance = 0.3;
  reach.target = Eigen::Vector2d(5.0, 6.0);
  TaskMonitor monitor(one_step(reach), kDt);
  monitor.start_timer(world);
  world.avatar.pose.y = 5.69;
  tick(world);
  monitor.observe(world);
  CHECK(monitor.outcome() == TaskOutcome::None);
  world.avatar.pose.y = 5.71;
  tick(world);
  monitor.observe(world);
  CHECK(monitor.outcome() == TaskOutcome::Completed);
}

TEST_CASE("the time limit gives a timeout at the exact tick, and nothing after") {
  World world = open_room();
  world.avatar.pose.yaw = std::acos(-1.0);
  TaskStep find;
  find.type = TaskType::FindRobot;
  TaskMonitor monitor(one_step(find, 2.0), kDt);
  tick(world);
  monitor.start_timer(world);  // at tick 1
  while (monitor.outcome() == TaskOutcome::None && world.tick < 1000) {
    tick(world);
    monitor.observe(world);
  }
  CHECK(monitor.outcome() == TaskOutcome::Timeout);
  CHECK(*monitor.outcome_tick() == 121);
  CHECK(monitor.status().time_left == 0.0);
  monitor.clear_events();
  world.avatar.pose.yaw = 0.0;  // found too late
  tick(world);
  monitor.observe(world);
  CHECK(monitor.events().empty());
  CHECK(monitor.outcome() == TaskOutcome::Timeout);
}

TEST_CASE("a spec without steps is inactive: no clock, no events, no outcome") {
  World world = open_room();
  TaskMonitor monitor(TaskSpec{}, kDt);
  CHECK_FALSE(monitor.active());
  monitor.start_timer(world);
  for (int i = 0; i < 100000; ++i) {
    tick(world);
    monitor.observe(world);
  }
  CHECK(monitor.events().empty());
  CHECK(monitor.outcome() == TaskOutcome::None);
  CHECK(task_text(TaskSpec{}, monitor.status(), "X").corner.empty());
}

namespace {

// Two steps (find the robot, then follow it), 12.7 of 30 s into the second, 3:12 left: what both HUD texts show.
std::pair<TaskSpec, TaskStatus> following_halfway() {
  TaskSpec spec;
  TaskStep find;
  find.type = TaskType::FindRobot;
  TaskStep follow;
  follow.type = TaskType::FollowRobot;
  spec.steps = {find, follow};
  TaskStatus status;
  status.timer_running = true;
  status.step = 1;
  status.amount = 12.7;
  status.goal = 30.0;
  status.time_left = 191.2;
  return {spec, status};
}

}  // namespace

TEST_CASE("the HUD says the step, the instruction, the progress and the time left, then the code") {
  auto [spec, status] = following_halfway();
  const TaskText running = task_text(spec, status, "");
  CHECK(running.corner ==
        std::vector<std::string>{"Task 2 of 2", "Follow the robot: stay close to it", "Following: 12 / 30 s", "Time left 3:12"});
  CHECK(running.centre.empty());
  status.outcome = TaskOutcome::Timeout;
  const TaskText over = task_text(spec, status, "T-2");
  CHECK(over.corner.empty());
  CHECK(over.centre == std::vector<std::string>{"Time is up. Thank you!", "Your completion code:", "T-2"});
  status.outcome = TaskOutcome::Completed;
  CHECK(task_text(spec, status, "").centre == std::vector<std::string>{"Task complete. Thank you!"});
}

TEST_CASE("a replay's watcher sees the step count, progress, time left and outcome, not the walker's prompts") {
  auto [spec, status] = following_halfway();
  CHECK(watched_task_text(spec, status).corner ==
        std::vector<std::string>{"Task 2 of 2", "Following: 12 / 30 s", "Time left 3:12"});
  status.step = 0;
  CHECK(watched_task_text(spec, status).corner == std::vector<std::string>{"Task 1 of 2", "Time left 3:12"});
  status.outcome = TaskOutcome::Timeout;
  CHECK(watched_task_text(spec, status).corner.empty());
  CHECK(watched_task_text(spec, status).centre == std::vector<std::string>{"The time ran out."});
  status.outcome = TaskOutcome::Completed;
  CHECK(watched_task_text(spec, status).centre == std::vector<std::string>{"The task was completed."});
  CHECK(watched_task_text(TaskSpec{}, status) == TaskText{});
}
