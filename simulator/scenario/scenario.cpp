// SPDX-License-Identifier: GPL-2.0-or-later
// Scenario files: parsing, checking against the map, overrides, and the initial world.
#include "scenario/scenario.hpp"

#include <charconv>
#include <cmath>
#include <numbers>
#include <sstream>

#include "map/map_server_loader.hpp"
#include "scenario/robot_params_yaml.hpp"
#include "scenario/task_yaml.hpp"
#include "scenario/yaml_field.hpp"

namespace rfbsim::sim {

namespace {

// Bounds that catch typos (a pose in millimetres, a crowd of 15000) without limiting real studies.
constexpr double kMaxCoordinate = 1.0e4;  // m
constexpr int kMaxPeople = 500;
constexpr int kMaxRepeat = 200;
constexpr double kAvatarClearance = 0.25;  // m, the avatar's body radius (world.hpp, Avatar)
constexpr double kRobotClearance = 0.16;  // m, Kuri's footprint

std::string known_spawn_names(const Scenario& scenario) {
  std::string names;
  for (const auto& spawn : scenario.spawns) names += (names.empty() ? "" : ", ") + spawn.name;
  return names.empty() ? "none defined" : names;
}

const SpawnPoint* find_spawn(const Scenario& scenario, const std::string& name) {
  for (const auto& spawn : scenario.spawns) {
    if (spawn.name == name) return &spawn;
  }
  return nullptr;
}

std::uint32_t parse_colour(const YamlField& field) {
  const std::string text = field.text();
  std::uint32_t value = 0;
  if (text.size() == 7 && text[0] == '#') {
    const auto [end, ec] = std::from_chars(text.data() + 1, text.data() + 7, value, 16);
    if (ec == std::errc() && end == text.data() + 7) return value;
  }
  field.fail("a colour as a quoted \"#rrggbb\"");
}

// [x, y] or [x, y, yaw] (yaw in radians).
Pose2 parse_literal_pose(const YamlField& field, bool yaw_allowed) {
  const auto items = field.sequence(2, yaw_allowed ? 3 : 2);
  Pose2 pose;
  pose.x = items[0].number(-kMaxCoordinate, kMaxCoordinate);
  pose.y = items[1].number(-kMaxCoordinate, kMaxCoordinate);
  if (items.size() == 3) pose.yaw = items[2].number(-4.0 * std::numbers::pi, 4.0 * std::numbers::pi);
  return pose;
}

// A place: a spawn point's name, or [x, y(, yaw)]. `name` gets the spawn's name or "".
Pose2 parse_place(const Scenario& scenario, const YamlField& field, std::string* name = nullptr) {
  if (field.is_scalar()) {
    const std::string wanted = field.text();
    const SpawnPoint* spawn = find_spawn(scenario, wanted);
    if (spawn == nullptr) field.fail_with("no spawn point '" + wanted + "' (known: " + known_spawn_names(scenario) + ")");
    if (name != nullptr) *name = wanted;
    return spawn->pose;
  }
  if (!field.is_sequence()) field.fail("a spawn point's name or [x, y, yaw]");
  if (name != nullptr) name->clear();
  return parse_literal_pose(field, true);
}

// A pose must be on the map and leave room for a body of `clearance` radius.
void check_free(const Scenario& scenario, const GridMap& obstacles, const Pose2& pose, double clearance,
                const std::string& what, const YamlField* field) {
  std::ostringstream where;
  where << "(" << pose.x << ", " << pose.y << ")";
  std::string problem;
  if (!scenario.map.contains(pose.x, pose.y)) {
    problem = what + " " + where.str() + " is off the map";
  } else if (obstacles.disc_hits_wall(pose.x, pose.y, clearance)) {
    problem = what + " " + where.str() + " is inside or against a wall or prop";
  }
  if (problem.empty()) return;
  if (field != nullptr) field->fail_with(problem);
  throw ScenarioError(scenario.file.string() + ": " + problem);
}

GridMap obstacles_of(const Scenario& scenario) { return with_props_blocked(scenario.map, scenario.props); }

void parse_props(Scenario& scenario, const YamlField& list) {
  for (const YamlField& item : list.sequence()) {
    item.allow_only({"kind", "pose", "size", "color", "repeat"});
    Prop prop;
    const YamlField kind = item.required("kind");
    const std::string kind_name = kind.text();
    if (kind_name == "box") {
      prop.kind = PropKind::Box;
      prop.rgb = 0xb08850;
    } else if (kind_name == "shelf") {
      prop.kind = PropKind::Shelf;
      prop.rgb = 0x2f5f9e;
    } else if (kind_name == "desk") {
      prop.kind = PropKind::Desk;
      prop.rgb = 0xb9a27e;
    } else {
      kind.fail("box, shelf or desk");
    }
    const Pose2 pose = parse_literal_pose(item.required("pose"), true);
    prop.x = pose.x;
    prop.y = pose.y;
    prop.yaw = pose.yaw;
    const auto size = item.required("size").sequence(3, 3);
    prop.size_x = size[0].number(0.05, 100.0);
    prop.size_y = size[1].number(0.05, 100.0);
    prop.height = size[2].number(0.05, 20.0);
    if (auto colour = item.optional("color")) prop.rgb = parse_colour(*colour);
    // `repeat` places a row of equal props: aisles of shelving in one entry.
    int count = 1;
    Eigen::Vector2d step = Eigen::Vector2d::Zero();
    if (auto repeat = item.optional("repeat")) {
      repeat->allow_only({"count", "step"});
      count = repeat->required("count").integer(1, kMaxRepeat);
      const auto offset = repeat->required("step").sequence(2, 2);
      step = {offset[0].number(-100.0, 100.0), offset[1].number(-100.0, 100.0)};
    }
    for (int i = 0; i < count; ++i) {
      Prop placed = prop;
      placed.x += step.x() * i;
      placed.y += step.y() * i;
      if (!scenario.map.contains(placed.x, placed.y)) {
        item.fail_with("prop " + std::to_string(i + 1) + " of this entry is off the map");
      }
      scenario.props.push_back(placed);
    }
  }
}

void parse_crowd(Scenario& scenario, const GridMap& obstacles, const YamlField& crowd, bool seed_given) {
  crowd.allow_only({"count", "seed", "speed", "routes", "goals"});
  CrowdSpec& spec = scenario.crowd;
  spec.count = crowd.required("count").integer(0, kMaxPeople);
  if (auto seed = crowd.optional("seed")) {
    spec.seed = seed->unsigned_integer();
  } else if (seed_given) {
    spec.seed = scenario.seed;
  }
  if (auto speed = crowd.optional("speed")) {
    speed->allow_only({"mean", "std", "min", "max"});
    if (auto v = speed->optional("mean")) spec.speed_mean = v->number(0.1, 3.0);
    if (auto v = speed->optional("std")) spec.speed_std = v->number(0.0, 1.5);
    if (auto v = speed->optional("min")) spec.speed_min = v->number(0.05, 3.0);
    if (auto v = speed->optional("max")) spec.speed_max = v->number(0.1, 4.0);
    if (spec.speed_min > spec.speed_max) speed->fail_with("min is above max");
  }
  const auto place_on_floor = [&](const YamlField& field) {
    const Pose2 pose = parse_place(scenario, field);
    check_free(scenario, obstacles, pose, 0.2, "this point", &field);
    return Eigen::Vector2d(pose.x, pose.y);
  };
  if (auto routes = crowd.optional("routes")) {
    for (const YamlField& route : routes->sequence(1)) {
      std::vector<Eigen::Vector2d> points;
      for (const YamlField& point : route.sequence(2)) points.push_back(place_on_floor(point));
      spec.routes.push_back(std::move(points));
    }
  }
  if (auto goals = crowd.optional("goals")) {
    for (const YamlField& goal : goals->sequence(2)) spec.goals.push_back(place_on_floor(goal));
  }
  if (spec.count > 0 && spec.routes.empty() && spec.goals.empty()) {
    crowd.fail_with("a crowd needs 'routes' or 'goals' (at least two places) to walk between");
  }
}

void parse_robot(Scenario& scenario, const YamlField& robot) {
  robot.allow_only({"start", "mission", "nav", "control", "command_timeout"});
  if (auto nav = robot.optional("nav")) parse_robot_params(*nav, scenario.robot.params);
  if (auto control = robot.optional("control")) {
    const auto parsed = robot_control_from_name(control->text());
    if (!parsed) control->fail_with("expected 'builtin' or 'external'");
    scenario.robot.control = *parsed;
  }
  if (auto timeout = robot.optional("command_timeout")) {
    scenario.robot.command_timeout = timeout->number(0.05, 60.0);
  }
  scenario.robot.present = true;
  scenario.robot.start = parse_place(scenario, robot.required("start"));
  auto mission_field = robot.optional("mission");
  if (!mission_field) return;
  mission_field->allow_only({"type", "goal", "waypoints"});
  MissionSpec& mission = scenario.robot.mission;
  const YamlField type = mission_field->required("type");
  const std::string kind = type.text();
  const auto add = [&](const YamlField& place) {
    std::string name;
    // The SEAN-EP study sent the robot to where the participant started.
    if (place.is_scalar() && place.text() == "avatar_start") {
      mission.waypoints.push_back(scenario.avatar_start);
      mission.waypoint_names.emplace_back("avatar_start");
      return;
    }
    mission.waypoints.push_back(parse_place(scenario, place, &name));
    mission.waypoint_names.push_back(name);
  };
  if (kind == "goto") {
    mission.kind = MissionSpec::Kind::GoTo;
    add(mission_field->required("goal"));
  } else if (kind == "patrol" || kind == "wander") {
    mission.kind = kind == "patrol" ? MissionSpec::Kind::Patrol : MissionSpec::Kind::Wander;
    for (const YamlField& place : mission_field->required("waypoints").sequence(2)) add(place);
  } else if (kind == "none") {
    mission.kind = MissionSpec::Kind::None;
  } else {
    type.fail("goto, patrol, wander or none");
  }
}

Landmark goal_landmark(const Pose2& at, const std::string& name) {
  Landmark goal;
  goal.name = name.empty() ? "goal" : name;
  goal.x = at.x;
  goal.y = at.y;
  goal.radius = 0.3;  // SEAN-EP counted success within 0.3 m of the goal
  return goal;
}

void parse_avatar(Scenario& scenario, const YamlField& avatar) {
  avatar.allow_only({"start", "goal"});
  scenario.avatar_start = parse_place(scenario, avatar.required("start"));
  if (auto goal = avatar.optional("goal")) {
    // A landmark's name, a spawn point's name, or [x, y].
    if (goal->is_scalar()) {
      for (const Landmark& landmark : scenario.landmarks) {
        if (landmark.name == goal->text()) {
          scenario.avatar_goal = landmark;
          return;
        }
      }
    }
    std::string name;
    scenario.avatar_goal = goal_landmark(parse_place(scenario, *goal, &name), name);
  }
}

// "x,y" or "x,y,yaw": every part a finite number, nothing else.
std::optional<Pose2> parse_pose_text(const std::string& text) {
  std::vector<double> parts;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data() + start, text.data() + comma, value);
    if (ec != std::errc() || end != text.data() + comma || !std::isfinite(value) || std::abs(value) > kMaxCoordinate) {
      return std::nullopt;
    }
    parts.push_back(value);
    start = comma + 1;
  }
  if (parts.size() < 2 || parts.size() > 3) return std::nullopt;
  return Pose2{parts[0], parts[1], parts.size() == 3 ? parts[2] : 0.0};
}

Pose2 resolve_override(const Scenario& scenario, const std::string& option, const std::string& value,
                       std::string* name) {
  if (const SpawnPoint* spawn = find_spawn(scenario, value)) {
    if (name != nullptr) *name = value;
    return spawn->pose;
  }
  if (auto pose = parse_pose_text(value)) {
    if (name != nullptr) name->clear();
    return *pose;
  }
  throw ScenarioError(option + ": '" + value + "' is neither a spawn point of " + scenario.name + " (known: " +
                      known_spawn_names(scenario) + ") nor x,y or x,y,yaw");
}

}  // namespace

Scenario load_scenario(const std::filesystem::path& file) {
  const YamlField root = read_yaml_file(file);
  if (!root.is_mapping()) root.fail("a mapping of scenario keys");
  root.allow_only({"name", "description", "map", "seed", "props", "landmarks", "spawns", "crowd", "robot", "avatar", "task",
                   "camera"});
  Scenario scenario;
  scenario.file = file;
  scenario.name = root.optional("name") ? root.required("name").text() : file.stem().string();
  if (auto camera = root.optional("camera")) {
    const auto mode = camera_mode_from_name(camera->text());
    if (!mode) camera->fail_with("expected 'third_person' or 'first_person'");
    scenario.camera = *mode;
  }

  // The map first: every pose below is checked against it.
  const YamlField map_field = root.required("map");
  scenario.map_file = map_field.text();
  if (scenario.map_file.is_relative()) scenario.map_file = file.parent_path() / scenario.map_file;
  try {
    LoadedMap loaded = load_ros_map(scenario.map_file);
    scenario.map_image = loaded.meta.image;
    scenario.map = std::move(loaded.grid);
  } catch (const MapLoadError& e) {
    map_field.fail_with(e.what());
  }

  const bool seed_given = root.optional("seed").has_value();
  if (seed_given) scenario.seed = root.required("seed").unsigned_integer();
  scenario.crowd.seed = scenario.seed;
  if (auto props = root.optional("props")) parse_props(scenario, *props);
  const GridMap obstacles = obstacles_of(scenario);

  if (auto spawns = root.optional("spawns")) {
    for (const auto& [name, pose_field] : spawns->mapping()) {
      if (find_spawn(scenario, name) != nullptr) pose_field.fail_with("spawn point '" + name + "' is defined twice");
      const Pose2 pose = parse_literal_pose(pose_field, true);
      check_free(scenario, obstacles, pose, kRobotClearance, "spawn point '" + name + "'", &pose_field);
      scenario.spawns.push_back({name, pose});
    }
  }
  if (auto landmarks = root.optional("landmarks")) {
    for (const YamlField& item : landmarks->sequence()) {
      item.allow_only({"name", "position", "radius", "color"});
      Landmark landmark;
      landmark.name = item.required("name").text();
      const Pose2 at = parse_place(scenario, item.required("position"));
      landmark.x = at.x;
      landmark.y = at.y;
      if (auto radius = item.optional("radius")) landmark.radius = radius->number(0.05, 5.0);
      if (auto colour = item.optional("color")) landmark.rgb = parse_colour(*colour);
      scenario.landmarks.push_back(landmark);
    }
  }
  parse_avatar(scenario, root.required("avatar"));
  check_free(scenario, obstacles, scenario.avatar_start, kAvatarClearance, "avatar.start", nullptr);
  if (auto robot = root.optional("robot")) {
    parse_robot(scenario, *robot);
    check_free(scenario, obstacles, scenario.robot.start, kRobotClearance, "robot.start", nullptr);
    // Waypoints given as coordinates as well as by spawn name (those were checked with the spawns).
    for (const Pose2& waypoint : scenario.robot.mission.waypoints) {
      check_free(scenario, obstacles, waypoint, kRobotClearance, "robot.mission place", nullptr);
    }
  }
  if (auto crowd = root.optional("crowd")) parse_crowd(scenario, obstacles, *crowd, seed_given);
  if (auto task = root.optional("task")) {
    scenario.task = parse_task(*task, scenario.landmarks);
    try {
      resolve_task_targets(scenario.task, scenario.landmarks, scenario.avatar_goal ? &*scenario.avatar_goal : nullptr);
    } catch (const ScenarioError& e) {
      task->fail_with(e.what());
    }
  }
  return scenario;
}

std::filesystem::path find_scenario(const std::string& name_or_path,
                                    const std::vector<std::filesystem::path>& search_dirs) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(name_or_path, ec)) return name_or_path;
  // A bare name only: a path-like name that does not exist must not be looked up elsewhere.
  const bool bare = name_or_path.find('/') == std::string::npos && !name_or_path.empty() &&
                    name_or_path.find("..") == std::string::npos;
  std::string known;
  for (const auto& dir : search_dirs) {
    if (bare && std::filesystem::is_regular_file(dir / (name_or_path + ".yaml"), ec)) return dir / (name_or_path + ".yaml");
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
      if (entry.path().extension() == ".yaml") known += (known.empty() ? "" : ", ") + entry.path().stem().string();
    }
  }
  throw ScenarioError("scenario '" + name_or_path + "' not found (no such file, and no such name; known: " +
                      (known.empty() ? std::string("none") : known) + ")");
}

void apply_overrides(Scenario& scenario, const ScenarioOverrides& overrides) {
  const GridMap obstacles = obstacles_of(scenario);
  if (overrides.seed) {
    scenario.seed = *overrides.seed;
    scenario.crowd.seed = *overrides.seed;
  }
  if (overrides.crowd_count) {
    if (*overrides.crowd_count < 0 || *overrides.crowd_count > kMaxPeople) {
      throw ScenarioError("--crowd: expected 0.." + std::to_string(kMaxPeople) + " people");
    }
    if (*overrides.crowd_count > 0 && scenario.crowd.routes.empty() && scenario.crowd.goals.empty()) {
      throw ScenarioError("--crowd: scenario " + scenario.name + " defines no routes or goals for a crowd");
    }
    scenario.crowd.count = *overrides.crowd_count;
  }
  const auto checked = [&](const char* option, const std::string& value, double clearance, std::string* name) {
    const Pose2 pose = resolve_override(scenario, option, value, name);
    try {
      check_free(scenario, obstacles, pose, clearance, std::string(option) + " '" + value + "'", nullptr);
    } catch (const ScenarioError& e) {
      throw ScenarioError(std::string(option) + ": " + e.what());
    }
    return pose;
  };
  if (overrides.avatar_start) {
    scenario.avatar_start = checked("--avatar-start", *overrides.avatar_start, kAvatarClearance, nullptr);
    // A robot sent to the participant's start follows the start it was sent to.
    auto& mission = scenario.robot.mission;
    for (std::size_t i = 0; i < mission.waypoints.size(); ++i) {
      if (mission.waypoint_names[i] == "avatar_start") mission.waypoints[i] = scenario.avatar_start;
    }
  }
  if (overrides.avatar_goal) {
    std::string name;
    const Pose2 goal = checked("--avatar-goal", *overrides.avatar_goal, 0.05, &name);
    scenario.avatar_goal = goal_landmark(goal, name);
    // Reach steps without a landmark of their own go to the goal the link gave.
    resolve_task_targets(scenario.task, scenario.landmarks, &*scenario.avatar_goal);
  }
  if (overrides.robot_start || overrides.robot_goal || overrides.robot_control) {
    if (!scenario.robot.present) {
      throw ScenarioError("--robot-start/--robot-goal/--robot-control: scenario " + scenario.name + " has no robot");
    }
  }
  if (overrides.robot_control) {
    const auto control = robot_control_from_name(*overrides.robot_control);
    if (!control) {
      throw ScenarioError("--robot-control: expected 'builtin' or 'external', got '" + *overrides.robot_control + "'");
    }
    scenario.robot.control = *control;
  }
  if (overrides.camera) {
    const auto mode = camera_mode_from_name(*overrides.camera);
    if (!mode) {
      throw ScenarioError("--camera: expected 'third_person' or 'first_person', got '" + *overrides.camera + "'");
    }
    scenario.camera = *mode;
  }
  if (overrides.robot_start) scenario.robot.start = checked("--robot-start", *overrides.robot_start, kRobotClearance, nullptr);
  if (overrides.robot_goal) {
    std::string name;
    const Pose2 goal = checked("--robot-goal", *overrides.robot_goal, kRobotClearance, &name);
    scenario.robot.mission.kind = MissionSpec::Kind::GoTo;
    scenario.robot.mission.waypoints = {goal};
    scenario.robot.mission.waypoint_names = {name};
  }
}

RobotSetup robot_setup(const Scenario& scenario) {
  RobotSetup setup;
  setup.params = scenario.robot.params;
  setup.mission = scenario.robot.mission;
  setup.control = scenario.robot.control;
  setup.command_timeout = scenario.robot.command_timeout;
  // The robot's streams (lidar noise, odometry drift, particles, wander picks) apart from the crowd's.
  setup.seed = scenario.seed * 0x9e3779b97f4a7c15ULL + 0x726f626f74ULL;
  return setup;
}

World make_world(const Scenario& scenario) {
  World world;
  world.map = scenario.map;
  world.props = scenario.props;
  world.obstacles = obstacles_of(scenario);
  world.landmarks = scenario.landmarks;
  if (scenario.avatar_goal) {
    bool listed = false;
    for (const Landmark& landmark : world.landmarks) listed = listed || landmark.name == scenario.avatar_goal->name;
    if (!listed) world.landmarks.push_back(*scenario.avatar_goal);
  }
  world.avatar.pose = scenario.avatar_start;
  if (scenario.robot.present) {
    Robot robot;
    robot.pose = scenario.robot.start;
    robot.estimate = robot.pose;
    world.robot = robot;
  }
  return world;
}

}  // namespace rfbsim::sim
