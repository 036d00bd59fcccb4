// SPDX-License-Identifier: GPL-2.0-or-later
// SessionCatalog: session folders from several data folders, with their hosts, repeats left out.
#include "session_catalog.hpp"

#include <map>
#include <utility>

#include <nlohmann/json.hpp>

#include "record/session_log.hpp"
#include "small_file.hpp"

namespace rfbsim::tools {

namespace {

// manager.json is a few hundred bytes; a larger file is not what we look for and is not read into memory.
constexpr std::uintmax_t kMaxRecordBytes = 64 * 1024;
constexpr std::size_t kMaxHostBytes = 64;

// The data folder as given, without a trailing separator ("data/" and "data" are one host).
std::string folder_label(const std::filesystem::path& data_dir) {
  std::filesystem::path normal = data_dir.lexically_normal();
  if (!normal.has_filename() && normal.has_parent_path() && normal != normal.root_path()) normal = normal.parent_path();
  return normal.string();
}

bool plausible_host(const std::string& host) {
  if (host.empty() || host.size() > kMaxHostBytes) return false;
  for (const char c : host) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == '/') return false;
  }
  return true;
}

}  // namespace

std::string host_from_layout(const std::filesystem::path& data_dir, const std::filesystem::path& relative) {
  // The folder holding the session, or the one above it when that is a host's "sessions" folder.
  std::filesystem::path above = relative.lexically_normal().parent_path();
  if (!above.empty() && above.filename() == "sessions") above = above.parent_path();
  if (above.empty() || above == ".") return folder_label(data_dir);
  return above.filename().string();
}

std::optional<std::string> recorded_host(const std::filesystem::path& dir) {
  const std::optional<std::string> bytes = read_small_file(dir / "manager.json", kMaxRecordBytes);
  if (!bytes) return std::nullopt;
  const nlohmann::json doc = nlohmann::json::parse(*bytes, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return std::nullopt;
  const auto it = doc.find("host");
  if (it == doc.end() || !it->is_string()) return std::nullopt;
  std::string host = it->get<std::string>();
  if (!plausible_host(host)) return std::nullopt;
  return host;
}

SessionCatalog catalog_sessions(const std::vector<std::filesystem::path>& data_dirs) {
  SessionCatalog catalog;
  std::map<std::filesystem::path, std::size_t> by_place;                   // the folder on disk
  std::map<std::pair<std::string, std::string>, std::size_t> by_host_name;  // (host, folder name)
  std::map<std::string, std::vector<std::size_t>> by_name;                  // folder name
  std::map<std::size_t, std::optional<std::string>> session_json;           // read once, when compared

  const auto session_json_of = [&](std::size_t index, const std::filesystem::path& dir) {
    auto it = session_json.find(index);
    if (it == session_json.end()) {
      it = session_json.emplace(index, read_small_file(dir / "session.json", kMaxSessionJsonBytes)).first;
    }
    return it->second;
  };

  for (std::size_t root = 0; root < data_dirs.size(); ++root) {
    for (const std::filesystem::path& dir : sim::find_session_dirs(data_dirs[root])) {
      FoundSession found;
      found.dir = dir;
      found.root = root;
      found.relative = dir.lexically_relative(data_dirs[root]);
      if (found.relative.empty()) found.relative = ".";
      if (std::optional<std::string> host = recorded_host(dir)) {
        found.host = std::move(*host);
        found.host_recorded = true;
      } else {
        found.host = host_from_layout(data_dirs[root], found.relative);
      }
      std::error_code ec;
      std::filesystem::path place = std::filesystem::weakly_canonical(dir, ec);
      if (ec) place = std::filesystem::absolute(dir, ec).lexically_normal();
      const std::string name = place.filename().string();

      // Is it a session already in the catalog? The cheapest tests first; session.json is read only
      // when two folders share a name but not a host, and one of the hosts is only a guess.
      std::optional<RepeatedSession> repeat;
      if (const auto it = by_place.find(place); it != by_place.end()) {
        repeat = RepeatedSession{dir, it->second, "the same folder, under two of the data folders"};
      } else if (const auto it2 = by_host_name.find({found.host, name}); it2 != by_host_name.end()) {
        repeat = RepeatedSession{dir, it2->second, "the same host (" + found.host + ") and folder name"};
      } else if (const auto it3 = by_name.find(name); it3 != by_name.end()) {
        const std::optional<std::string> mine = read_small_file(dir / "session.json", kMaxSessionJsonBytes);
        for (const std::size_t other : it3->second) {
          // Two hosts that both recorded their ids (and differ) ran two sessions, however alike.
          if (found.host_recorded && catalog.sessions[other].host_recorded) continue;
          const std::optional<std::string> theirs = session_json_of(other, catalog.sessions[other].dir);
          if (mine && theirs && *mine == *theirs) {
            repeat = RepeatedSession{dir, other, "the same folder name and an identical session.json"};
            break;
          }
        }
      }
      if (repeat) {
        catalog.repeats.push_back(std::move(*repeat));
        continue;
      }
      const std::size_t index = catalog.sessions.size();
      by_place.emplace(place, index);
      by_host_name.emplace(std::make_pair(found.host, name), index);
      by_name[name].push_back(index);
      catalog.sessions.push_back(std::move(found));
    }
  }
  return catalog;
}

}  // namespace rfbsim::tools
