// SPDX-License-Identifier: GPL-2.0-or-later
// SessionWriter: session.json, trajectories.csv and events.jsonl.
#include "record/session_writer.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <stdexcept>
#include <utility>

#include "record/file_io.hpp"

namespace rfbsim::sim {

namespace {

constexpr std::size_t kBufferLimit = 256 * 1024;  // bytes: handed over at once above this, whatever the clock

[[noreturn]] void fail(const std::filesystem::path& dir, const std::string& what) {
  throw std::runtime_error(dir.string() + ": " + what);
}

const char* party_name(Party party) {
  switch (party) {
    case Party::Avatar: return "avatar";
    case Party::Person: return "person";
    case Party::Robot: return "robot";
    case Party::Static: return "static";
  }
  return "unknown";
}

// Ids as in trajectories.csv: the person's own id, 0 for the others.
int party_id(const World& world, Party party, int index) {
  if (party != Party::Person || index < 0 || static_cast<std::size_t>(index) >= world.people.size()) return 0;
  return world.people[static_cast<std::size_t>(index)].id;
}

// Six decimals, with -0.000000 written as 0.000000: a replay compares the text, and a sign that rounds
// away must not make two equal poses differ.
double printable(double value) { return std::abs(value) < 5e-7 ? 0.0 : value; }

void append_row(std::string& out, std::uint64_t tick, double time, const char* kind, int id, const Pose2& pose,
                const Eigen::Vector2d& velocity) {
  char row[256];
  std::snprintf(row, sizeof row, "%llu,%.6f,%s,%d,%.6f,%.6f,%.6f,%.6f,%.6f\n", static_cast<unsigned long long>(tick),
                time, kind, id, printable(pose.x), printable(pose.y), printable(pose.yaw), printable(velocity.x()),
                printable(velocity.y()));
  out += row;
}

}  // namespace

std::string iso_utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const auto millis =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[80];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900, utc.tm_mon + 1,
                utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, static_cast<int>(millis));
  return text;
}

SessionWriter::SessionWriter(std::filesystem::path dir, SessionInfo info, const World& world,
                             std::chrono::milliseconds flush_interval)
    : SessionWriter(std::move(dir), std::move(info), world, SessionWriterOptions{flush_interval, {}, {}}) {}

SessionWriter::SessionWriter(std::filesystem::path dir, SessionInfo info, const World& world,
                             SessionWriterOptions options)
    : dir_(std::move(dir)), info_(std::move(info)), flush_interval_(options.flush_interval) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw std::runtime_error(dir_.string() + ": cannot create the session folder (" + ec.message() + ")");
  // Appending a second session to a first one's files would mix them beyond repair.
  if (std::filesystem::exists(dir_ / "session.json", ec)) {
    throw std::runtime_error(dir_.string() + ": already holds a session (session.json); record into a new folder");
  }
  if (info_.trajectory_hz < 1 || info_.tick_hz % info_.trajectory_hz != 0) {
    throw std::runtime_error("trajectory rate " + std::to_string(info_.trajectory_hz) + " Hz must divide the tick rate " +
                             std::to_string(info_.tick_hz) + " Hz");
  }
  sample_every_ = static_cast<std::uint64_t>(info_.tick_hz / info_.trajectory_hz);

  using json = nlohmann::ordered_json;
  json parameters = json::object();
  for (const auto& [name, value] : info_.parameters) parameters[name] = value;
  json agents = json::array();
  agents.push_back({{"kind", "avatar"}, {"id", 0}, {"radius", world.avatar.radius}});
  if (world.robot) agents.push_back({{"kind", "robot"}, {"id", 0}, {"radius", world.robot->radius}});
  for (const Person& p : world.people) agents.push_back({{"kind", "person"}, {"id", p.id}, {"radius", p.radius}});
  json tasks = json::array();
  for (const auto& [type, text] : info_.tasks) tasks.push_back({{"type", type}, {"text", text}});
  session_ = {{"format", "rfbsim-session/1"},
              {"uid", info_.uid},
              {"scenario", info_.scenario},
              {"scenario_file", info_.scenario_file},
              {"parameters", parameters},
              {"seed", std::to_string(info_.seed)},
              {"tick_hz", info_.tick_hz},
              {"fps", info_.fps},
              {"trajectory_hz", info_.trajectory_hz},
              {"frame", {{"width", info_.width}, {"height", info_.height}}},
              {"versions",
               {{"rfbsim", info_.rfbsim_version},
                {"build", info_.build},
                {"scenario_sha256", info_.scenario_sha256},
                {"map_sha256", info_.map_sha256}}},
              {"agents", agents},
              {"tasks", tasks},
              {"time_limit_s", info_.time_limit ? json(*info_.time_limit) : json(nullptr)},
              {"end_grace_s", info_.end_grace ? json(*info_.end_grace) : json(nullptr)},
              {"codes", info_.codes ? json{{"success", info_.codes->first}, {"timeout", info_.codes->second}}
                                    : json(nullptr)},
              {"robot_control", info_.robot_control.empty() ? json(nullptr) : json(info_.robot_control)},
              {"camera", info_.camera},
              // A watcher's session.json says "video" (app/watch_record.hpp): the study's two conditions.
              {"condition", "interactive"},
              {"ros",
               {{"bag", info_.ros_bag.empty() ? json(nullptr) : json(info_.ros_bag)},
                {"bridge", info_.ros_bridge.empty() ? json(nullptr) : json(info_.ros_bridge)},
                {"namespace", info_.ros_namespace.empty() ? json(nullptr) : json(info_.ros_namespace)}}},
              {"started_at", iso_utc_now()},
              {"ended_at", nullptr},
              {"end_tick", nullptr},
              {"end_reason", nullptr},
              {"outcome", nullptr},
              {"completion", nullptr},
              {"tasks_done", json::array()}};

  // The folder's start is written here, synced, before the session begins: at the start a folder that
  // cannot be written is an error, not a warning.
  std::string error;
  UniqueFd dir_fd = open_dir(dir_, error);
  if (!dir_fd.valid()) fail(dir_, error);
  const std::string document = session_.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
  if (const FileResult written = replace_file(dir_, dir_fd.get(), "session.json", document); !written.ok()) {
    fail(dir_, written.error);
  }
  std::vector<std::pair<std::string, UniqueFd>> files;
  for (const char* name : {"trajectories.csv", "events.jsonl"}) {
    UniqueFd fd = open_append(dir_ / name, error);
    if (!fd.valid()) throw std::runtime_error(error);
    files.emplace_back(name, std::move(fd));
  }
  FileResult header = write_all(files[0].second.get(), "tick,time,kind,id,x,y,yaw,vx,vy\n", files[0].first);
  if (header.ok()) header = sync_data(files[0].second.get(), files[0].first);
  if (header.ok()) header = sync_dir(dir_fd.get(), dir_.string());
  if (!header.ok()) fail(dir_, header.error);
  // The folder's own name, in a folder that create_directories may just have made.
  if (UniqueFd parent = open_dir(dir_.parent_path().empty() ? "." : dir_.parent_path(), error); parent.valid()) {
    sync_dir(parent.get(), dir_.parent_path().string());
  }
  last_flush_ = std::chrono::steady_clock::now();
  queue_ = std::make_unique<SyncQueue>(dir_, std::move(dir_fd), std::move(files), session_, options.limits,
                                       std::move(options.faults));
}

SessionWriter::~SessionWriter() {
  hand_over();
  queue_->close();
}

void SessionWriter::sample(const World& world) {
  if (world.tick % sample_every_ != 0) return;
  const double time = time_of(world.tick);
  append_row(trajectory_buffer_, world.tick, time, "avatar", 0, world.avatar.pose,
             Eigen::Vector2d(std::cos(world.avatar.pose.yaw), std::sin(world.avatar.pose.yaw)) * world.avatar.speed);
  if (world.robot) append_row(trajectory_buffer_, world.tick, time, "robot", 0, world.robot->pose, world.robot->velocity);
  for (const Person& p : world.people) append_row(trajectory_buffer_, world.tick, time, "person", p.id, p.pose, p.velocity);
}

void SessionWriter::event(std::uint64_t tick, const char* type, const nlohmann::ordered_json& fields) {
  nlohmann::ordered_json line = {{"tick", tick}, {"time", time_of(tick)}, {"type", type}};
  for (const auto& [key, value] : fields.items()) line[key] = value;
  // Strings from outside (robot details, task texts) may hold any bytes: replace what is not UTF-8
  // rather than throw in the middle of a session.
  const std::string text = line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  events_buffer_ += text;
  events_buffer_ += '\n';
  if (event_listener_) event_listener_(tick, text);
}

void SessionWriter::world_events(const World& world) {
  for (const ContactEvent& c : world.contacts) {
    event(c.tick, "contact",
          {{"a", party_name(c.a)}, {"a_id", party_id(world, c.a, c.a_index)}, {"b", party_name(c.b)},
           {"b_id", party_id(world, c.b, c.b_index)}, {"impulse", c.impulse}});
  }
  for (const RobotEvent& r : world.robot_events) {
    event(r.tick, "robot", {{"state", robot_state_name(r.state)}, {"detail", r.detail}});
  }
}

void SessionWriter::task_done(const std::string& type, std::uint64_t tick) {
  session_["tasks_done"].push_back({{"type", type}, {"tick", tick}, {"time", time_of(tick)}});
  hand_over();
  queue_->replace_document(session_);
}

void SessionWriter::outcome(const std::string& outcome, const std::string& code, std::uint64_t tick) {
  session_["outcome"] = outcome;
  session_["completion"] = {{"code", code}, {"tick", tick}, {"time", time_of(tick)}};
  // The outcome is what a study needs most: on disk now, with the lines that led to it.
  hand_over();
  queue_->replace_document(session_);
}

void SessionWriter::finish(const SessionEnd& end) {
  session_["ended_at"] = iso_utc_now();
  session_["end_tick"] = end.tick;
  session_["end_reason"] = end.reason;
  hand_over();
  queue_->replace_document(session_);
  queue_->close();
}

void SessionWriter::flush_if_due() {
  const auto now = std::chrono::steady_clock::now();
  if (now - last_flush_ >= flush_interval_ || trajectory_buffer_.size() + events_buffer_.size() > kBufferLimit) {
    hand_over();
  }
}

void SessionWriter::checkpoint() { hand_over(); }

bool SessionWriter::flush() {
  hand_over();
  queue_->drain();
  return !queue_->failure();
}

void SessionWriter::hand_over() {
  last_flush_ = std::chrono::steady_clock::now();
  // Whole lines per append: a kill between two writes leaves every line complete.
  queue_->append(SyncQueue::kTrajectory, std::exchange(trajectory_buffer_, {}));
  queue_->append(SyncQueue::kEvents, std::exchange(events_buffer_, {}));
  queue_->sync();
}

}  // namespace rfbsim::sim
