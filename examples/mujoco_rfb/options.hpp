// SPDX-License-Identifier: GPL-2.0-or-later
// mujoco_rfb's command line: what it serves, where, and how big.
#pragma once

#include <string>

namespace mujoco_rfb {

/// The settings the command line gives; start from the defaults.
struct Options {
  int port = 5902;                      ///< TCP port; 0 = any free one
  std::string bind = "127.0.0.1";       ///< numeric address to listen on
  std::string model;                    ///< MJCF file; empty = the bundled arm on a table
  int width = 640;                      ///< frame width in pixels, 160..3840
  int height = 480;                     ///< frame height in pixels, 120..2160
  std::string web_root;                 ///< page to serve over HTTP; empty = the built or installed one, if any
  bool rfb_only = false;                ///< serve no page at all (what sim_manager needs)
  std::string log_level = "info";       ///< librfbsim's log: error, warn, info or debug (rfbsim/log.hpp)
  bool help = false;                    ///< --help was given
};

/// What parse_options found: the options, or an error text naming the flag (then exit status 2).
struct Parsed {
  Options options;
  std::string error;  ///< empty when the command line was good
};

/// Parses argv[1..argc-1]. Never throws; a bad or unknown flag gives Parsed::error.
Parsed parse_options(int argc, const char* const* argv);

/// The usage text printed by --help and after an error.
std::string usage();

}  // namespace mujoco_rfb
