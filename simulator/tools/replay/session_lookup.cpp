// SPDX-License-Identifier: GPL-2.0-or-later
// lookup_session: a session by uid or id across data folders.
#include "session_lookup.hpp"

#include <nlohmann/json.hpp>

#include "small_file.hpp"

namespace rfbsim::replay {

namespace {

// session.json's uid, or none when the file cannot be read or has none.
std::optional<std::string> uid_of(const std::filesystem::path& dir) {
  const std::optional<std::string> bytes = tools::read_small_file(dir / "session.json", tools::kMaxSessionJsonBytes);
  if (!bytes) return std::nullopt;
  const nlohmann::json doc = nlohmann::json::parse(*bytes, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object() || !doc.contains("uid") || !doc["uid"].is_string()) return std::nullopt;
  return doc["uid"].get<std::string>();
}

// Whether the folder's name is `id`, or `id` is a session id (digits) and the name is "<id>-<uid>".
bool names_session(const std::filesystem::path& dir, const std::string& id) {
  const std::string name = dir.lexically_normal().filename().string();
  if (name == id) return true;
  const bool digits = !id.empty() && id.find_first_not_of("0123456789") == std::string::npos;
  return digits && name.size() > id.size() && name.compare(0, id.size(), id) == 0 && name[id.size()] == '-';
}

std::string list(const std::vector<std::filesystem::path>& dirs) {
  std::string out;
  for (const auto& dir : dirs) out += (out.empty() ? "" : ", ") + dir.string();
  return out;
}

}  // namespace

LookupResult lookup_session(const std::vector<std::filesystem::path>& data_dirs, const SessionQuery& query) {
  LookupResult result;
  for (const std::filesystem::path& dir : data_dirs) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) {
      result.error = dir.string() + ": no such folder";
      return result;
    }
  }

  // Every session, each once, then those the query names.
  const tools::SessionCatalog catalog = tools::catalog_sessions(data_dirs);
  std::vector<const tools::FoundSession*> matches;
  std::size_t unreadable = 0;
  for (const tools::FoundSession& s : catalog.sessions) {
    if (query.host && s.host != *query.host) continue;
    if (query.session && !names_session(s.dir, *query.session)) continue;
    if (query.uid) {
      const std::optional<std::string> uid = uid_of(s.dir);
      if (!uid) ++unreadable;
      if (uid != query.uid) continue;
    }
    matches.push_back(&s);
  }

  const std::string what = (query.uid ? "uid '" + *query.uid + "'" : "session '" + query.session.value_or("") + "'") +
                           (query.host ? " on host '" + *query.host + "'" : "");
  if (matches.size() == 1) {
    result.found = *matches.front();
  } else if (matches.empty()) {
    result.error = "no session of " + what + " under " + list(data_dirs) + " (" +
                   std::to_string(catalog.sessions.size()) + " sessions looked at";
    if (unreadable > 0) result.error += ", " + std::to_string(unreadable) + " without a readable session.json uid";
    result.error += ")";
  } else {
    result.error = what + " matches " + std::to_string(matches.size()) + " sessions:";
    for (const tools::FoundSession* s : matches) result.error += "\n  host " + s->host + ": " + s->dir.string();
    result.error += "\nname one with --host HOST (or give its SESSION_DIR)";
  }
  return result;
}

}  // namespace rfbsim::replay
