// SPDX-License-Identifier: GPL-2.0-or-later
// sim_replay's command line: each option declared once with CLI11, from which parsing and --help follow.
#include "replay_cli.hpp"

#include "cli/command_line.hpp"

namespace rfbsim::replay {

namespace {

// What the command line gives that ReplayOptions keeps in another form.
struct ReplayArgs {
  std::vector<std::string> positional;  // SESSION_DIR, once
  std::vector<std::string> data_dirs;
  std::string video, out_dir;
  std::string view = "participant";
  bool check_only = false;
};

// Declares sim_replay's arguments on `app`, bound to `options` and `given`.
void declare_replay_cli(CLI::App& app, ReplayOptions& options, ReplayArgs& given) {
  using cli::non_empty;
  cli::configure(app);
  app.description(
      "   or: sim_replay --data-dir DIR [--data-dir DIR...] (--uid UID | --session ID) [--host HOST] [options]\n"
      "\n"
      "Re-runs a recorded session (a folder with session.json, trajectories.csv and events.jsonl, as\n"
      "sim_rfb --data-dir writes it) from its scenario, seed and recorded inputs, and checks that every\n"
      "pose in trajectories.csv comes out the same, to the last digit. With --video it also renders the\n"
      "session as the participant saw it (or from above) into an H.264 MP4 at the recorded frame size\n"
      "and frame rate.");
  app.footer(
      "Exit status: 0 the replay matches the log (and the video was written); 1 failure (no GL, no H.264\n"
      "encoder, a write failed); 2 usage errors, unreadable session data, or a refused replay (another\n"
      "version or build, a changed scenario or map; see --force); 3 the replay differs from the log (the\n"
      "first differing line is printed; the video, if any, is not kept unless --force).");
  app.add_flag("-h,--help", options.help, "print this help and exit");
  app.add_option("SESSION_DIR", given.positional, "the recorded session's folder");
  app.add_option("--data-dir", given.data_dirs,
                 "look for the session under DIR (repeat it for several hosts' data folders or the\n"
                 "shared store <store>/<host_id>/<folder>/) instead of giving its SESSION_DIR")
      ->type_name("DIR")->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)->check(non_empty());
  app.add_option("--uid", options.uid, "the session of participant UID (session.json's uid)")
      ->type_name("UID")->check(non_empty());
  app.add_option("--session", options.session, "the session folder named ID (3-p003), or the manager's session id (3)")
      ->type_name("ID")->check(non_empty());
  app.add_option("--host", options.host,
                 "only sessions of HOST (manager.json's host, else the store folder's name); use it\n"
                 "when UID or ID matches sessions of several hosts (listed in the error)")
      ->type_name("HOST")->check(non_empty());
  app.add_option("--video", given.video, "write the video to FILE (MP4, H.264, yuv420p; replaced if it exists)")
      ->type_name("FILE")->check(non_empty());
  cli::one_of(app.add_option("--view", given.view,
                             "participant (the participant's camera and HUD) or top (the whole map\n"
                             "from above, with the HUD)")
                  ->capture_default_str(),
              {"participant", "top"});
  app.add_flag("--check-only", given.check_only, "only check the poses (the default without --video)");
  app.add_option("--out-dir", given.out_dir,
                 "keep the replay's own session.json, trajectories.csv and events.jsonl in DIR\n"
                 "(a new or empty folder; default: a temporary folder, removed at the end)")
      ->type_name("DIR")->check(non_empty());
  app.add_flag("--force", options.force,
               "replay even when the log was recorded by another rfbsim version or build, or\n"
               "its scenario or map changed since (warns; the poses will likely differ)");
  app.add_flag("-q,--quiet", options.quiet, "no progress line on stderr");
  cli::add_log_level(app, options.log_level);
}

}  // namespace

std::optional<ReplayOptions> parse_cli(const std::vector<std::string>& args, CliError& error) {
  ReplayOptions options;
  ReplayArgs given;
  CLI::App app("", "sim_replay");
  declare_replay_cli(app, options, given);
  error.message = cli::parse(app, args);
  if (!error.message.empty()) return std::nullopt;
  if (options.help) return options;
  const std::vector<std::string>& positional = given.positional;
  const bool check_only = given.check_only;
  const bool view_given = app.count("--view") > 0;
  options.view = given.view == "top" ? View::Top : View::Participant;
  if (!given.video.empty()) options.video = given.video;
  if (!given.out_dir.empty()) options.out_dir = given.out_dir;
  options.data_dirs.assign(given.data_dirs.begin(), given.data_dirs.end());
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
  ReplayOptions options;
  ReplayArgs given;
  CLI::App app("", "sim_replay");
  declare_replay_cli(app, options, given);
  return app.help();
}

}  // namespace rfbsim::replay
