// SPDX-License-Identifier: GPL-2.0-or-later
// SessionLog: reading and checking a session folder (docs/data.md).
#include "record/session_log.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <string_view>
#include <system_error>
#include <type_traits>

namespace rfbsim::sim {

namespace {

using json = nlohmann::json;

constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 30;  // a session is megabytes; more is garbage
constexpr const char* kFormat = "rfbsim-session/1";
constexpr const char* kTrajectoryHeader = "tick,time,kind,id,x,y,yaw,vx,vy";

// Where a problem is: the file, and the 1-based line for the line-oriented files (0: the whole file).
struct Where {
  std::filesystem::path file;
  std::size_t line = 0;

  [[noreturn]] void fail(const std::string& what) const {
    std::string at = file.string();
    if (line > 0) at += ":" + std::to_string(line);
    throw SessionLogError(at + ": " + what);
  }
};

std::string read_file(const std::filesystem::path& file) {
  const Where where{file};
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) where.fail("missing (or not a file)");
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec) where.fail("cannot read (" + ec.message() + ")");
  if (size > kMaxFileBytes) where.fail("larger than 1 GiB: not session data");
  std::ifstream in(file, std::ios::binary);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(size))) where.fail("cannot read");
  return bytes;
}

// The complete lines of an appended file; a last line without its newline is counted in `torn` and dropped.
std::vector<std::string_view> complete_lines(std::string_view bytes, std::size_t& torn) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  for (std::size_t nl = bytes.find('\n'); nl != std::string_view::npos; nl = bytes.find('\n', start)) {
    lines.push_back(bytes.substr(start, nl - start));
    start = nl + 1;
  }
  if (start < bytes.size()) ++torn;
  return lines;
}

// ---- JSON keys, each checked with a message naming it ----

const json& need(const json& object, const std::string& key, const Where& where) {
  const auto it = object.find(key);
  if (it == object.end()) where.fail("missing key '" + key + "'");
  return *it;
}

[[noreturn]] void wrong(const std::string& key, const char* expected, const Where& where) {
  where.fail("key '" + key + "': expected " + expected);
}

std::string get_string(const json& object, const std::string& key, const Where& where) {
  const json& value = need(object, key, where);
  if (!value.is_string()) wrong(key, "a string", where);
  return value.get<std::string>();
}

std::optional<std::string> get_optional_string(const json& object, const std::string& key, const Where& where) {
  if (need(object, key, where).is_null()) return std::nullopt;
  return get_string(object, key, where);
}

std::int64_t get_integer(const json& object, const std::string& key, std::int64_t low, std::int64_t high,
                         const Where& where) {
  const json& value = need(object, key, where);
  const std::string range = "an integer " + std::to_string(low) + ".." + std::to_string(high);
  if (value.is_number_unsigned()) {
    const std::uint64_t n = value.get<std::uint64_t>();
    if (n > static_cast<std::uint64_t>(high) || (low > 0 && n < static_cast<std::uint64_t>(low))) {
      wrong(key, range.c_str(), where);
    }
    return static_cast<std::int64_t>(value.get<std::uint64_t>());
  }
  if (!value.is_number_integer() || value.get<std::int64_t>() < low || value.get<std::int64_t>() > high) {
    wrong(key, range.c_str(), where);
  }
  return value.get<std::int64_t>();
}

std::uint64_t get_tick(const json& object, const std::string& key, const Where& where) {
  const json& value = need(object, key, where);
  if (!value.is_number_unsigned()) wrong(key, "a tick (an integer 0 or more)", where);
  return value.get<std::uint64_t>();
}

double get_number(const json& object, const std::string& key, const Where& where) {
  const json& value = need(object, key, where);
  if (!value.is_number() || !std::isfinite(value.get<double>())) wrong(key, "a number", where);
  return value.get<double>();
}

bool get_bool(const json& object, const std::string& key, const Where& where) {
  const json& value = need(object, key, where);
  if (!value.is_boolean()) wrong(key, "true or false", where);
  return value.get<bool>();
}

const json& get_object(const json& object, const std::string& key, const Where& where) {
  const json& value = need(object, key, where);
  if (!value.is_object()) wrong(key, "an object", where);
  return value;
}

const json& get_array(const json& object, const std::string& key, const Where& where) {
  const json& value = need(object, key, where);
  if (!value.is_array()) wrong(key, "an array", where);
  return value;
}

std::optional<AgentKind> parse_kind(std::string_view text) {
  if (text == "avatar") return AgentKind::Avatar;
  if (text == "robot") return AgentKind::Robot;
  if (text == "person") return AgentKind::Person;
  return std::nullopt;
}

// ---- session.json ----

SessionMeta parse_meta(const json& doc, const Where& where) {
  if (!doc.is_object()) where.fail("not a JSON object");
  const std::string format = get_string(doc, "format", where);
  if (format != kFormat) where.fail("format '" + format + "' is not " + kFormat);

  SessionMeta meta;
  meta.uid = get_string(doc, "uid", where);
  meta.scenario = get_string(doc, "scenario", where);
  meta.scenario_file = get_string(doc, "scenario_file", where);
  for (const auto& [name, value] : get_object(doc, "parameters", where).items()) {
    if (!value.is_string()) wrong("parameters." + name, "a string", where);
    meta.parameters[name] = value.get<std::string>();
  }
  const std::string seed = get_string(doc, "seed", where);
  const auto [end, ec] = std::from_chars(seed.data(), seed.data() + seed.size(), meta.seed);
  if (seed.empty() || ec != std::errc() || end != seed.data() + seed.size()) {
    wrong("seed", "a decimal string of a 64-bit unsigned integer", where);
  }
  constexpr std::int64_t kMaxRate = 100000;  // Hz: catches garbage, limits no real configuration
  meta.tick_hz = static_cast<int>(get_integer(doc, "tick_hz", 1, kMaxRate, where));
  meta.fps = static_cast<int>(get_integer(doc, "fps", 1, kMaxRate, where));
  meta.trajectory_hz = static_cast<int>(get_integer(doc, "trajectory_hz", 1, kMaxRate, where));
  const json& frame = get_object(doc, "frame", where);
  meta.frame_width = static_cast<int>(get_integer(frame, "width", 0, 1 << 16, where));
  meta.frame_height = static_cast<int>(get_integer(frame, "height", 0, 1 << 16, where));
  const json& versions = get_object(doc, "versions", where);
  meta.rfbsim_version = get_string(versions, "rfbsim", where);
  meta.build = get_string(versions, "build", where);
  meta.scenario_sha256 = get_string(versions, "scenario_sha256", where);
  meta.map_sha256 = get_string(versions, "map_sha256", where);

  for (const json& agent : get_array(doc, "agents", where)) {
    if (!agent.is_object()) wrong("agents", "an array of objects", where);
    const std::string kind = get_string(agent, "kind", where);
    const auto parsed = parse_kind(kind);
    if (!parsed) where.fail("agents: unknown kind '" + kind + "'");
    const double radius = get_number(agent, "radius", where);
    if (!(radius > 0.0 && radius < 100.0)) wrong("radius", "a body radius in metres (0..100)", where);
    meta.agents.push_back({*parsed, static_cast<int>(get_integer(agent, "id", 0, 1 << 30, where)), radius});
  }
  // trajectories.csv is read against this list: one avatar, at most one robot, people with distinct ids.
  const auto count = [&](AgentKind kind) {
    return std::count_if(meta.agents.begin(), meta.agents.end(), [&](const SessionAgent& a) { return a.kind == kind; });
  };
  if (count(AgentKind::Avatar) != 1 || count(AgentKind::Robot) > 1) {
    wrong("agents", "one avatar and at most one robot", where);
  }
  std::set<std::pair<AgentKind, int>> seen;
  for (const SessionAgent& a : meta.agents) {
    if (!seen.insert({a.kind, a.id}).second) {
      where.fail("agents: " + std::string(agent_kind_name(a.kind)) + " " + std::to_string(a.id) + " is listed twice");
    }
  }
  for (const json& task : get_array(doc, "tasks", where)) {
    if (!task.is_object()) wrong("tasks", "an array of objects", where);
    meta.tasks.push_back({get_string(task, "type", where), get_string(task, "text", where)});
  }
  if (!need(doc, "time_limit_s", where).is_null()) meta.time_limit_s = get_number(doc, "time_limit_s", where);
  // Optional: files written before --end-grace existed ran with their scenario's end_grace.
  if (const auto grace = doc.find("end_grace_s"); grace != doc.end() && !grace->is_null()) {
    meta.end_grace_s = get_number(doc, "end_grace_s", where);
  }
  // Optional: sessions recorded before the first-person view had the third-person one.
  if (const auto camera = doc.find("camera"); camera != doc.end() && !camera->is_null()) {
    const std::string name = get_string(doc, "camera", where);
    const auto mode = camera_mode_from_name(name);
    if (!mode) wrong("camera", "'third_person' or 'first_person'", where);
    meta.camera = *mode;
  }
  if (!need(doc, "codes", where).is_null()) {
    const json& codes = get_object(doc, "codes", where);
    meta.success_code = get_optional_string(codes, "success", where);
    meta.timeout_code = get_optional_string(codes, "timeout", where);
  }
  meta.started_at = get_string(doc, "started_at", where);
  meta.ended_at = get_optional_string(doc, "ended_at", where);
  if (!need(doc, "end_tick", where).is_null()) meta.end_tick = get_tick(doc, "end_tick", where);
  meta.end_reason = get_optional_string(doc, "end_reason", where);
  meta.outcome = get_optional_string(doc, "outcome", where);
  if (!need(doc, "completion", where).is_null()) {
    const json& completion = get_object(doc, "completion", where);
    SessionCompletion c;
    c.code = get_string(completion, "code", where);
    c.tick = get_tick(completion, "tick", where);
    c.time = get_number(completion, "time", where);
    meta.completion = c;
  }
  for (const json& done : get_array(doc, "tasks_done", where)) {
    if (!done.is_object()) wrong("tasks_done", "an array of objects", where);
    TaskDone d;
    d.type = get_string(done, "type", where);
    d.tick = get_tick(done, "tick", where);
    d.time = get_number(done, "time", where);
    meta.tasks_done.push_back(d);
  }
  // Only in folders whose recording failed (and in none older than the key).
  if (const auto it = doc.find("data_incomplete"); it != doc.end() && !it->is_null()) {
    if (!it->is_object()) wrong("data_incomplete", "an object", where);
    meta.data_incomplete = get_string(*it, "reason", where);
    meta.dropped_bytes = static_cast<std::uint64_t>(
        get_integer(*it, "dropped_bytes", 0, std::numeric_limits<std::int64_t>::max(), where));
  }
  return meta;
}

// ---- trajectories.csv ----

template <typename T>
T parse_field(std::string_view text, const char* column, const Where& where) {
  T value{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  bool good = !text.empty() && ec == std::errc() && end == text.data() + text.size();
  if constexpr (std::is_floating_point_v<T>) good = good && std::isfinite(value);
  if (!good) where.fail("column '" + std::string(column) + "': bad number '" + std::string(text.substr(0, 40)) + "'");
  return value;
}

using AgentSet = std::set<std::pair<AgentKind, int>>;

TrajectoryRow parse_row(std::string_view line, const AgentSet& agents, const Where& where) {
  std::string_view cells[9];
  std::size_t count = 0, start = 0;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i < line.size() && line[i] != ',') continue;
    if (count < 9) cells[count] = line.substr(start, i - start);
    ++count;
    start = i + 1;
  }
  if (count != 9) where.fail("expected 9 columns, got " + std::to_string(count));

  TrajectoryRow row;
  row.tick = parse_field<std::uint64_t>(cells[0], "tick", where);
  row.time = parse_field<double>(cells[1], "time", where);
  const auto kind = parse_kind(cells[2]);
  if (!kind) where.fail("unknown kind '" + std::string(cells[2].substr(0, 40)) + "'");
  row.kind = *kind;
  row.id = parse_field<int>(cells[3], "id", where);
  if (agents.count({row.kind, row.id}) == 0) {
    where.fail(std::string(agent_kind_name(row.kind)) + " " + std::to_string(row.id) +
               " is not among session.json's agents");
  }
  row.x = parse_field<double>(cells[4], "x", where);
  row.y = parse_field<double>(cells[5], "y", where);
  row.yaw = parse_field<double>(cells[6], "yaw", where);
  row.vx = parse_field<double>(cells[7], "vx", where);
  row.vy = parse_field<double>(cells[8], "vy", where);
  return row;
}

std::vector<TrajectoryRow> parse_trajectory(const std::filesystem::path& file, const SessionMeta& meta,
                                            std::size_t& torn) {
  const std::string bytes = read_file(file);
  const std::vector<std::string_view> lines = complete_lines(bytes, torn);
  Where where{file, 1};
  if (lines.empty()) where.fail("no header line");
  if (lines[0] != kTrajectoryHeader) where.fail(std::string("header is not '") + kTrajectoryHeader + "'");
  AgentSet agents;
  for (const SessionAgent& a : meta.agents) agents.insert({a.kind, a.id});
  std::vector<TrajectoryRow> rows;
  rows.reserve(lines.size() - 1);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    where.line = i + 1;
    rows.push_back(parse_row(lines[i], agents, where));
    if (rows.size() > 1 && rows.back().tick < rows[rows.size() - 2].tick) where.fail("tick goes backwards");
  }
  return rows;
}

// ---- events.jsonl ----

// The keys docs/data.md gives each event type, and what each holds.
enum class Holds { String, Integer, Boolean, Number };
struct KeySpec {
  const char* key;
  Holds holds;
};
struct TypeSpec {
  const char* type;
  std::vector<KeySpec> keys;
};

const std::vector<TypeSpec>& event_specs() {
  using H = Holds;
  static const std::vector<TypeSpec> specs = {
      {"session", {{"event", H::String}}},
      {"key", {{"keysym", H::Integer}, {"down", H::Boolean}, {"client", H::Integer}}},
      {"pointer", {{"x", H::Integer}, {"y", H::Integer}, {"buttons", H::Integer}, {"client", H::Integer}}},
      {"client", {{"event", H::String}, {"client", H::Integer}, {"address", H::String}, {"websocket", H::Boolean}}},
      {"contact",
       {{"a", H::String}, {"a_id", H::Integer}, {"b", H::String}, {"b_id", H::Integer}, {"impulse", H::Number}}},
      {"robot", {{"state", H::String}, {"detail", H::String}}},
      {"task", {{"event", H::String}, {"index", H::Integer}, {"task", H::String}, {"text", H::String}}},
      {"timer", {{"event", H::String}}},
      {"outcome", {{"outcome", H::String}, {"code", H::String}}},
  };
  return specs;
}

void check_event_keys(const Event& event, const Where& where) {
  for (const TypeSpec& spec : event_specs()) {
    if (event.type != spec.type) continue;
    for (const KeySpec& k : spec.keys) {
      switch (k.holds) {
        case Holds::String: get_string(event.fields, k.key, where); break;
        case Holds::Integer: get_integer(event.fields, k.key, std::numeric_limits<std::int64_t>::min(),
                                         std::numeric_limits<std::int64_t>::max(), where); break;
        case Holds::Boolean: get_bool(event.fields, k.key, where); break;
        case Holds::Number: get_number(event.fields, k.key, where); break;
      }
    }
  }
}

std::vector<Event> parse_events(const std::filesystem::path& file, std::size_t& torn) {
  const std::string bytes = read_file(file);
  std::vector<Event> events;
  Where where{file, 0};
  for (const std::string_view line : complete_lines(bytes, torn)) {
    ++where.line;
    json object;
    try {
      object = json::parse(line.begin(), line.end());
    } catch (const json::exception& e) {
      where.fail(std::string("not JSON (") + e.what() + ")");
    }
    if (!object.is_object()) where.fail("not a JSON object");
    Event event;
    event.tick = get_tick(object, "tick", where);
    event.time = get_number(object, "time", where);
    event.type = get_string(object, "type", where);
    object.erase("tick");
    object.erase("time");
    object.erase("type");
    event.fields = std::move(object);
    check_event_keys(event, where);
    events.push_back(std::move(event));
  }
  return events;
}

}  // namespace

const char* agent_kind_name(AgentKind kind) {
  switch (kind) {
    case AgentKind::Avatar: return "avatar";
    case AgentKind::Robot: return "robot";
    case AgentKind::Person: return "person";
  }
  return "unknown";
}

const std::string& Event::text(const char* key) const {
  static const std::string none;
  const auto it = fields.find(key);
  return it != fields.end() && it->is_string() ? it->get_ref<const std::string&>() : none;
}

std::int64_t Event::integer(const char* key, std::int64_t fallback) const {
  const auto it = fields.find(key);
  if (it == fields.end() || !it->is_number_integer()) return fallback;
  if (it->is_number_unsigned() && it->get<std::uint64_t>() > std::numeric_limits<std::int64_t>::max()) return fallback;
  return it->get<std::int64_t>();
}

bool Event::flag(const char* key) const {
  const auto it = fields.find(key);
  return it != fields.end() && it->is_boolean() && it->get<bool>();
}

std::vector<std::string> read_complete_lines(const std::filesystem::path& file) {
  const std::string bytes = read_file(file);
  std::size_t torn = 0;
  const std::vector<std::string_view> views = complete_lines(bytes, torn);
  return {views.begin(), views.end()};
}

SessionLog read_session(const std::filesystem::path& dir) {
  SessionLog log;
  log.dir = dir;
  const std::filesystem::path session_file = dir / "session.json";
  const std::string text = read_file(session_file);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    Where{session_file}.fail(std::string("not JSON (") + e.what() + ")");
  }
  log.meta = parse_meta(doc, Where{session_file});
  log.trajectory = parse_trajectory(dir / "trajectories.csv", log.meta, log.torn_lines);
  log.events = parse_events(dir / "events.jsonl", log.torn_lines);
  return log;
}

std::vector<std::filesystem::path> find_session_dirs(const std::filesystem::path& data_dir) {
  std::vector<std::filesystem::path> found;
  std::error_code ec;
  if (!std::filesystem::is_directory(data_dir, ec)) return found;
  if (std::filesystem::is_regular_file(data_dir / "session.json", ec)) found.push_back(data_dir);
  std::filesystem::recursive_directory_iterator it(
      data_dir, std::filesystem::directory_options::skip_permission_denied, ec);
  // Walk with error codes throughout: an unreadable folder is passed over, never thrown out of.
  for (; !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
    std::error_code entry_ec;
    if (it->is_directory(entry_ec) && !it->is_symlink(entry_ec) &&
        std::filesystem::is_regular_file(it->path() / "session.json", entry_ec)) {
      found.push_back(it->path());
    }
  }
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace rfbsim::sim
