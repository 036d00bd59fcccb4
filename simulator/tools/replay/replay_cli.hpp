// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay's command line: `sim_replay SESSION_DIR [--video FILE] [--view participant|top] [--check-only]
// [--out-dir DIR] [--force] [--log-level L]`, or the session found by uid or id across hosts' data folders with
// `--data-dir DIR... --uid UID|--session ID [--host HOST]` in place of SESSION_DIR; `--help`. Pure: parsing only.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::replay {

/// Which camera the video shows.
enum class View {
  Participant,  ///< what the participant saw: session.json's camera (third or first person) and the HUD
  Top,          ///< a bird's-eye view of the whole map (SceneStyle::top_view)
};

/// What the command line asks for.
struct ReplayOptions {
  bool help = false;                          ///< --help / -h: print usage_text() and exit 0
  std::filesystem::path session_dir;          ///< SESSION_DIR: a folder with session.json (docs/data.md)
  /// --data-dir DIR (repeated): hosts' data folders or the shared store to find the session in (by --uid or
  /// --session) instead of SESSION_DIR; session_dir is then set by the caller (lookup_session).
  std::vector<std::filesystem::path> data_dirs;
  std::optional<std::string> uid;      ///< --uid: the session of this participant (session.json's uid)
  std::optional<std::string> session;  ///< --session: a folder name ("3-p003") or the manager's session id ("3")
  std::optional<std::string> host;     ///< --host: only sessions of this host
  std::optional<std::filesystem::path> video; ///< --video FILE: write an H.264 MP4; none = check only
  View view = View::Participant;              ///< --view
  std::optional<std::filesystem::path> out_dir;  ///< --out-dir: keep the replay's own session data here
  bool force = false;                         ///< --force: replay despite a different build or scenario
  bool quiet = false;                         ///< --quiet: no progress line
  std::string log_level = "info";             ///< --log-level: error, warn, info or debug (rfbsim/log.hpp)
};

/// A command line that cannot be run (exit 2); the message says what is wrong.
struct CliError {
  std::string message;
};

/// Parses the arguments after the program's name. Returns the options, or sets `error` and returns none.
std::optional<ReplayOptions> parse_cli(const std::vector<std::string>& args, CliError& error);

/// The --help text.
std::string usage_text();

}  // namespace rfbsim::replay
