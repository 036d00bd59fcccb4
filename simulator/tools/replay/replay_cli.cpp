// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay's command line.
#include "replay_cli.hpp"

#include "cli_option.hpp"

namespace rfbsim::replay {

using tools::is_option;
using tools::option_value;

std::optional<ReplayOptions> parse_cli(const std::vector<std::string>& args, CliError& error) {
  ReplayOptions options;
  std::vector<std::string> positional;
  bool check_only = false;
  bool view_given = false;
  bool options_end = false;  // after "--" everything is a path, even "-x"
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (options_end || arg.empty() || arg[0] != '-' || arg == "-") {
      positional.push_back(arg);
    } else if (arg == "--") {
      options_end = true;
    } else if (arg == "--help" || arg == "-h") {
      options.help = true;
      return options;
    } else if (is_option(arg, "--video")) {
      const auto value = option_value(args, i, "--video", "a file name (out.mp4)", error.message);
      if (!value) return std::nullopt;
      options.video = *value;
    } else if (is_option(arg, "--out-dir")) {
      const auto value = option_value(args, i, "--out-dir", "a folder", error.message);
      if (!value) return std::nullopt;
      options.out_dir = *value;
    } else if (is_option(arg, "--view")) {
      const auto value = option_value(args, i, "--view", "participant or top", error.message);
      if (!value) return std::nullopt;
      if (*value == "participant") {
        options.view = View::Participant;
      } else if (*value == "top") {
        options.view = View::Top;
      } else {
        error.message = "--view: expected participant or top, got '" + *value + "'";
        return std::nullopt;
      }
      view_given = true;
    } else if (is_option(arg, "--data-dir")) {
      const auto value = option_value(args, i, "--data-dir", "a folder", error.message);
      if (!value) return std::nullopt;
      options.data_dirs.emplace_back(*value);
    } else if (is_option(arg, "--uid")) {
      const auto value = option_value(args, i, "--uid", "a participant id", error.message);
      if (!value) return std::nullopt;
      options.uid = *value;
    } else if (is_option(arg, "--session")) {
      const auto value = option_value(args, i, "--session", "a session folder's name or id", error.message);
      if (!value) return std::nullopt;
      options.session = *value;
    } else if (is_option(arg, "--host")) {
      const auto value = option_value(args, i, "--host", "a host id", error.message);
      if (!value) return std::nullopt;
      options.host = *value;
    } else if (arg == "--check-only") {
      check_only = true;
    } else if (arg == "--force") {
      options.force = true;
    } else if (arg == "--quiet" || arg == "-q") {
      options.quiet = true;
    } else {
      error.message = "unknown option '" + arg + "'";
      return std::nullopt;
    }
  }
  // Either the session's folder, or where to look for it and which one.
  if (!options.data_dirs.empty()) {
    if (!positional.empty()) {
      error.message = "give SESSION_DIR or --data-dir with --uid or --session, not both";
      return std::nullopt;
    }
    if (options.uid.has_value() == options.session.has_value()) {
      error.message = options.uid ? "--uid and --session: give one of them"
                                  : "--data-dir needs --uid UID or --session ID (which session to replay)";
      return std::nullopt;
    }
  } else if (options.uid || options.session || options.host) {
    error.message = std::string(options.uid ? "--uid" : options.session ? "--session" : "--host") +
                    " picks a session under --data-dir folders: give --data-dir DIR (or the SESSION_DIR alone)";
    return std::nullopt;
  } else if (positional.size() != 1 || positional[0].empty()) {
    error.message = positional.empty() ? "SESSION_DIR is missing" : "expected one SESSION_DIR";
    return std::nullopt;
  }
  if (check_only && options.video) {
    error.message = "--check-only writes no video: give --video or --check-only, not both";
    return std::nullopt;
  }
  if (view_given && !options.video) {
    error.message = "--view chooses the video's camera: it needs --video FILE";
    return std::nullopt;
  }
  if (options.data_dirs.empty()) options.session_dir = positional[0];
  return options;
}

std::string usage_text() {
  return "Usage: sim_replay SESSION_DIR [--video FILE] [--view participant|top] [--check-only]\n"
         "                  [--out-dir DIR] [--force] [--quiet]\n"
         "       sim_replay --data-dir DIR [--data-dir DIR...] (--uid UID | --session ID) [--host HOST] [options]\n"
         "\n"
         "Re-runs a recorded session (a folder with session.json, trajectories.csv and events.jsonl, as\n"
         "sim_rfb --data-dir writes it) from its scenario, seed and recorded inputs, and checks that every\n"
         "pose in trajectories.csv comes out the same, to the last digit. With --video it also renders the\n"
         "session as the participant saw it (or from above) into an H.264 MP4 at the recorded frame size\n"
         "and frame rate.\n"
         "\n"
         "Options:\n"
         "  --data-dir DIR     look for the session under DIR (repeat it for several hosts' data folders or the\n"
         "                     shared store <store>/<host_id>/<folder>/) instead of giving its SESSION_DIR\n"
         "  --uid UID          the session of participant UID (session.json's uid)\n"
         "  --session ID       the session folder named ID (3-p003), or the manager's session id (3)\n"
         "  --host HOST        only sessions of HOST (manager.json's host, else the store folder's name); use it\n"
         "                     when UID or ID matches sessions of several hosts (listed in the error)\n"
         "  --video FILE       write the video to FILE (MP4, H.264, yuv420p; replaced if it exists)\n"
         "  --view VIEW        participant (default: the participant's camera and HUD) or top (the whole map\n"
         "                     from above, with the HUD)\n"
         "  --check-only       only check the poses (the default without --video)\n"
         "  --out-dir DIR      keep the replay's own session.json, trajectories.csv and events.jsonl in DIR\n"
         "                     (a new or empty folder; default: a temporary folder, removed at the end)\n"
         "  --force            replay even when the log was recorded by another rfbsim version or build, or\n"
         "                     its scenario or map changed since (warns; the poses will likely differ)\n"
         "  -q, --quiet        no progress line on stderr\n"
         "  -h, --help         this text\n"
         "\n"
         "Exit status: 0 the replay matches the log (and the video was written); 1 failure (no GL, no H.264\n"
         "encoder, a write failed); 2 usage errors, unreadable session data, or a refused replay (another\n"
         "version or build, a changed scenario or map; see --force); 3 the replay differs from the log (the\n"
         "first differing line is printed; the video, if any, is not kept unless --force).\n";
}

}  // namespace rfbsim::replay
