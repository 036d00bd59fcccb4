// SPDX-License-Identifier: GPL-2.0-or-later
// A watcher's session.json: peeked at for its condition, and read in full.
#include "watcher_session.hpp"

#include <nlohmann/json.hpp>

#include "json_record.hpp"
#include "small_file.hpp"

namespace rfbsim::tools {

namespace {

using json = nlohmann::json;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw WatcherSessionError(file.string() + ": " + what);
}

using Record = JsonRecord<WatcherSessionError>;

// A non-negative integer key of `object`; absent or null is none.
std::optional<std::uint64_t> count(const Record& record, const json& object, const char* key,
                                   const std::string& where = "") {
  const json* value = Record::present(object, key);
  if (!value) return std::nullopt;
  if (!value->is_number_unsigned()) record.fail("key '" + where + key + "': expected a whole number");
  return value->get<std::uint64_t>();
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
  const Record doc(bytes, file);
  if (const auto condition = doc.text("condition", false); condition && *condition != "video") {
    doc.fail("key 'condition': '" + *condition + "' in a watcher's session (expected video)");
  }

  WatcherSession w;
  w.uid = *doc.text("uid", true);
  w.yoked_to = doc.integer("yoked_to", "an integer or null");
  w.yoked_to_uid_hash = doc.text("yoked_to_uid_hash", false).value_or("");
  w.camera = doc.text("camera", false).value_or("");
  w.started_at = *doc.text("started_at", true);
  w.ended_at = doc.text("ended_at", false);
  w.end_tick = count(doc, doc.doc(), "end_tick");
  w.end_reason = doc.text("end_reason", false);
  w.outcome = doc.text("outcome", false);
  w.viewers = static_cast<std::int64_t>(count(doc, doc.doc(), "viewers").value_or(0));

  // What was shown: the source as its own session.json described it.
  const json* source = Record::present(doc.doc(), "replay_of");
  if (!source) doc.fail("key 'replay_of': missing");
  if (!source->is_object()) doc.fail("key 'replay_of': expected an object");
  w.source_started_at = doc.text("started_at", false, source, "replay_of.").value_or("");
  w.source_seed = doc.text("seed", false, source, "replay_of.").value_or("");
  w.source_end_tick = count(doc, *source, "end_tick", "replay_of.");
  const std::optional<std::string> source_scenario = doc.text("scenario", false, source, "replay_of.");
  w.scenario = doc.text("scenario", false).value_or(source_scenario.value_or(""));
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
