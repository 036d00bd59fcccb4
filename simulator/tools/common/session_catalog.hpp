// SPDX-License-Identifier: GPL-2.0-or-later
// SessionCatalog: a study's session folders gathered from several data folders (hosts' data folders
// `DIR/sessions/<id>-<uid>/`, the shared store `<store>/<host_id>/<folder>/`, or a merged copy of them),
// each with the host that ran it, and the same session found twice kept once. sim_report and sim_replay
// find sessions through it (docs/report.md, "Several hosts").
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::tools {

/// One session folder found under one of the data folders.
struct FoundSession {
  std::filesystem::path dir;       ///< the folder as found: data folder / relative
  std::size_t root = 0;            ///< index of the data folder it was found under
  std::filesystem::path relative;  ///< `dir` relative to that data folder ("." when the data folder is the session)
  std::string host;                ///< manager.json's `host`, else host_from_layout()
  bool host_recorded = false;      ///< `host` is manager.json's (not guessed from the layout)
};

/// A session folder found again and left out: another copy of a session already in the catalog.
struct RepeatedSession {
  std::filesystem::path dir;  ///< the folder left out
  std::size_t kept = 0;       ///< index into SessionCatalog::sessions of the copy kept (the first found)
  std::string why;            ///< how the two were recognised as one session, in words
};

/// Every session under a list of data folders.
struct SessionCatalog {
  std::vector<FoundSession> sessions;    ///< in the data folders' order, then sorted by path within each
  std::vector<RepeatedSession> repeats;  ///< in the order found
};

/// The host a session folder's place under `data_dir` names: in the store layout (`<host>/<folder>`, or
/// `<host>/sessions/<folder>` for a host's whole data folder copied under its id) the first component of
/// `relative`; otherwise (`sessions/<folder>`, or the session itself) the data folder as given, so that
/// two data folders never share a host unless their manager.json files say so.
std::string host_from_layout(const std::filesystem::path& data_dir, const std::filesystem::path& relative);

/// The `host` that sim_manager recorded in `dir`/manager.json: none when there is no such file, it is not
/// JSON, or its `host` is missing, not a string, empty, over 64 bytes or holds a control character or '/'.
/// Never throws (sim_report warns of a broken manager.json when it reads it in full).
std::optional<std::string> recorded_host(const std::filesystem::path& dir);

/// Finds every session folder (one holding a session.json: a watcher's of the video condition too, whose
/// session.json is all it holds; watcher_session.hpp tells them apart) under each of `data_dirs`, in order. A folder
/// is one session already in the catalog, and left out as a repeat, when it is the same folder on disk
/// (overlapping data folders), or has the same host and folder name (a host's data folder and the store
/// both given), or has the same folder name and a byte-identical session.json while one of the two hosts
/// is only guessed from the layout (a copy whose host could not be told). A data folder that is not a folder contributes nothing.
SessionCatalog catalog_sessions(const std::vector<std::filesystem::path>& data_dirs);

}  // namespace rfbsim::tools
