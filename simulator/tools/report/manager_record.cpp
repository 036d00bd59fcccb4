// SPDX-License-Identifier: GPL-2.0-or-later
// ManagerRecord: manager.json read and checked.
#include "manager_record.hpp"

#include <chrono>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string_view>

#include "json_record.hpp"

namespace rfbsim::report {

namespace {

// manager.json is a few hundred bytes; anything far larger is not one, and is not read into memory.
constexpr std::uintmax_t kMaxRecordBytes = 64 * 1024;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw ManagerRecordError(file.string() + ": " + what);
}

using Record = tools::JsonRecord<ManagerRecordError>;

// The time under `key` in ms since 1970; none when null (and `nullable`).
std::optional<long long> time(const Record& record, const char* key, bool nullable) {
  if (record.doc().find(key) == record.doc().end()) record.fail(std::string("key '") + key + "': missing");
  const std::optional<std::string> value = record.text(key, !nullable);
  if (!value) return std::nullopt;
  const std::optional<long long> millis = parse_utc_millis(*value);
  if (!millis) record.fail(std::string("key '") + key + "': expected an ISO 8601 UTC time, got '" + *value + "'");
  return millis;
}

bool known_state(std::string_view state) {
  std::string_view all = manager_states();
  while (!all.empty()) {
    const std::size_t space = all.find(' ');
    if (all.substr(0, space) == state) return true;
    all = space == std::string_view::npos ? std::string_view() : all.substr(space + 1);
  }
  return false;
}

// `count` digits at text[at...] as a number; none when any is not a digit.
std::optional<int> digits(const std::string& text, std::size_t at, std::size_t count) {
  if (at + count > text.size()) return std::nullopt;
  int value = 0;
  for (std::size_t i = at; i < at + count; ++i) {
    if (text[i] < '0' || text[i] > '9') return std::nullopt;
    value = value * 10 + (text[i] - '0');
  }
  return value;
}

}  // namespace

const char* manager_states() {
  return "starting running ending finished expired idle ended shutdown crashed failed interrupted abandoned";
}

std::optional<long long> parse_utc_millis(const std::string& text) {
  // YYYY-MM-DDTHH:MM:SS, then an optional fraction, then Z.
  const auto year = digits(text, 0, 4), month = digits(text, 5, 2), day = digits(text, 8, 2);
  const auto hour = digits(text, 11, 2), minute = digits(text, 14, 2), second = digits(text, 17, 2);
  if (!year || !month || !day || !hour || !minute || !second || text[4] != '-' || text[7] != '-' ||
      text[10] != 'T' || text[13] != ':' || text[16] != ':') {
    return std::nullopt;
  }
  std::size_t at = 19;
  long long millis = 0;
  if (at < text.size() && text[at] == '.') {
    const std::size_t first = ++at;
    while (at < text.size() && text[at] >= '0' && text[at] <= '9') ++at;
    const std::size_t count = at - first;
    if (count == 0 || count > 9) return std::nullopt;
    // Milliseconds from the first three digits (padded); finer digits are below the manager's resolution.
    for (std::size_t i = 0; i < 3; ++i) millis = millis * 10 + (i < count ? text[first + i] - '0' : 0);
  }
  if (at + 1 != text.size() || text[at] != 'Z') return std::nullopt;
  if (*hour > 23 || *minute > 59 || *second > 59) return std::nullopt;
  const std::chrono::year_month_day date{std::chrono::year(*year), std::chrono::month(static_cast<unsigned>(*month)),
                                         std::chrono::day(static_cast<unsigned>(*day))};
  if (!date.ok()) return std::nullopt;
  const long long days = std::chrono::sys_days(date).time_since_epoch().count();
  return ((days * 24 + *hour) * 60 + *minute) * 60'000LL + *second * 1000LL + millis;
}

ManagerRecord parse_manager_record(const std::string& bytes, const std::filesystem::path& file) {
  const Record doc(bytes, file);
  ManagerRecord record;
  record.uid = *doc.text("uid", true);
  record.state = *doc.text("state", true);
  if (!known_state(record.state)) doc.fail("key 'state': unknown state '" + record.state + "'");
  record.detail = doc.text("detail", false).value_or("");
  record.data_incomplete = doc.text("data_incomplete", false);
  record.host = doc.text("host", false);
  record.id = doc.integer("id", "an integer");

  // The study's condition (issue 33): a watcher names the session it watched; older files are interactive.
  record.condition = doc.text("condition", false).value_or("interactive");
  if (record.condition != "interactive" && record.condition != "video") {
    doc.fail("key 'condition': expected interactive or video, got '" + record.condition + "'");
  }
  record.yoked_to = doc.integer("yoked_to", "an integer");
  record.yoked_to_uid_hash = doc.text("yoked_to_uid_hash", false);

  // When the link was spent, counted from the manager creating the session (both on the manager's clock).
  const long long created = *time(doc, "created_at", false);
  if (const std::optional<long long> spent = time(doc, "spent_at", true)) {
    if (*spent < created) doc.fail("spent_at is before created_at");
    if (record.state == "abandoned") doc.fail("state 'abandoned' with a spent_at: an abandoned link is unspent");
    record.spent_after = static_cast<double>(*spent - created) / 1000.0;
  }
  return record;
}

std::optional<ManagerRecord> read_manager_record(const std::filesystem::path& dir) {
  const std::filesystem::path file = dir / "manager.json";
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  if (status.type() == std::filesystem::file_type::not_found) return std::nullopt;
  if (ec) fail(file, "cannot be read (" + ec.message() + ")");
  if (status.type() != std::filesystem::file_type::regular) fail(file, "not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec) fail(file, "cannot be read (" + ec.message() + ")");
  if (size > kMaxRecordBytes) fail(file, std::to_string(size) + " bytes: too large for a manager.json");

  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) fail(file, "cannot be read");
  return parse_manager_record(bytes.str(), file);
}

}  // namespace rfbsim::report
