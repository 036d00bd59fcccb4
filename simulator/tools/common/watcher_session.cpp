// SPDX-License-Identifier: GPL-2.0-or-later
// A watcher's session.json: peeked at for its condition, and read in full.
#include "watcher_session.hpp"

#include <nlohmann/json.hpp>

#include "small_file.hpp"

namespace rfbsim::tools {

namespace {

using json = nlohmann::json;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw WatcherSessionError(file.string() + ": " + what);
}

// The value under `key` of `doc` when it is there and not null.
const json* present(const json& doc, const char* key) {
  const auto it = doc.find(key);
  return it == doc.end() || it->is_null() ? nullptr : &*it;
}

// A string key; absent or null is none, or an error when `required`. `where` prefixes the key in errors
// ("replay_of." for the nested object).
std::optional<std::string> text(const json& doc, const char* key, const std::filesystem::path& file, bool required,
                                const std::string& where = "") {
  const json* value = present(doc, key);
  if (!value) {
    if (required) fail(file, "key '" + where + key + "': missing");
    return std::nullopt;
  }
  if (!value->is_string()) fail(file, "key '" + where + key + "': expected a string");
  return value->get<std::string>();
}

// A non-negative integer key; absent or null is none.
std::optional<std::uint64_t> count(const json& doc, const char* key, const std::filesystem::path& file,
                                   const std::string& where = "") {
  const json* value = present(doc, key);
  if (!value) return std::nullopt;
  if (!value->is_number_unsigned()) fail(file, "key '" + where + key + "': expected a whole number");
  return value->get<std::uint64_t>();
}

// An integer key (a manager's session id); absent or null is none.
std::optional<std::int64_t> integer(const json& doc, const char* key, const std::filesystem::path& file) {
  const json* value = present(doc, key);
  if (!value) return std::nullopt;
  if (!value->is_number_integer()) fail(file, std::string("key '") + key + "': expected an integer or null");
  return value->get<std::int64_t>();
}

}  // namespace

SessionKind peek_session_kind(const std::filesystem::path& dir) {
  SessionKind kind;
  const std::optional<std::string> bytes = read_small_file(dir / "session.json", kMaxSessionJsonBytes);
  if (!bytes) return kind;
  const json doc = json::parse(*bytes, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return kind;
  // `kind` came first (sim_rfb --replay's record before the conditions had names); either one is enough.
  const json condition = doc.value("condition", json());
  if (condition.is_string() && condition != "interactive" && condition != "video") {
    kind.unknown_condition = condition.get<std::string>();
    return kind;
  }
  kind.video = condition == "video" || doc.value("kind", json()) == "replay";
  if (kind.video) {
    const json yoked = doc.value("yoked_to", json());
    if (yoked.is_number_integer()) kind.yoked_to = yoked.get<std::int64_t>();
  }
  return kind;
}

WatcherSession parse_watcher_session(const std::string& bytes, const std::filesystem::path& file) {
  json doc;
  try {
    doc = json::parse(bytes);
  } catch (const json::exception& e) {
    fail(file, std::string("not JSON (") + e.what() + ")");
  }
  if (!doc.is_object()) fail(file, "expected a JSON object");
  if (const auto condition = text(doc, "condition", file, false); condition && *condition != "video") {
    fail(file, "key 'condition': '" + *condition + "' in a watcher's session (expected video)");
  }

  WatcherSession w;
  w.uid = *text(doc, "uid", file, true);
  w.yoked_to = integer(doc, "yoked_to", file);
  w.yoked_to_uid_hash = text(doc, "yoked_to_uid_hash", file, false).value_or("");
  w.camera = text(doc, "camera", file, false).value_or("");
  w.started_at = *text(doc, "started_at", file, true);
  w.ended_at = text(doc, "ended_at", file, false);
  w.end_tick = count(doc, "end_tick", file);
  w.end_reason = text(doc, "end_reason", file, false);
  w.outcome = text(doc, "outcome", file, false);
  w.viewers = static_cast<std::int64_t>(count(doc, "viewers", file).value_or(0));

  // What was shown: the source as its own session.json described it.
  const json* source = present(doc, "replay_of");
  if (!source) fail(file, "key 'replay_of': missing");
  if (!source->is_object()) fail(file, "key 'replay_of': expected an object");
  w.source_started_at = text(*source, "started_at", file, false, "replay_of.").value_or("");
  w.source_seed = text(*source, "seed", file, false, "replay_of.").value_or("");
  w.source_end_tick = count(*source, "end_tick", file, "replay_of.");
  const std::optional<std::string> source_scenario = text(*source, "scenario", file, false, "replay_of.");
  w.scenario = text(doc, "scenario", file, false).value_or(source_scenario.value_or(""));
  return w;
}

WatcherSession read_watcher_session(const std::filesystem::path& dir) {
  const std::filesystem::path file = dir / "session.json";
  const std::optional<std::string> bytes = read_small_file(file, kMaxSessionJsonBytes);
  if (!bytes) fail(file, "missing, unreadable or over 4 MiB");
  return parse_watcher_session(*bytes, file);
}

std::string watched_source(const std::optional<std::int64_t>& yoked_to) {
  return yoked_to ? "session " + std::to_string(*yoked_to) : std::string("a recording");
}

}  // namespace rfbsim::tools
