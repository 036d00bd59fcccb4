// SPDX-License-Identifier: GPL-2.0-or-later
// Checks of values that one program hands to another: sim_manager checks a link's uid and codes, its config's
// ROS namespace, rosbridge URL and origins, and sim_rfb checks the same values again on its command line. Both
// call these, so that a value the manager lets through is never one sim_rfb refuses. Pure, never throw.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace rfbsim::contract {

/// The longest identifier (uid, completion code, spawn point's name in a link, cluster host id), characters.
constexpr std::size_t kMaxIdentifier = 64;

/// The longest ROS graph name sim_rfb takes (--ros-namespace), characters.
constexpr std::size_t kMaxRosName = 512;
/// The longest namespace root sim_manager's config takes (ros.namespace), characters: each session's name is the
/// root plus "/s_<id>_<host id>", which must still fit kMaxRosName.
constexpr std::size_t kMaxRosRootName = 200;
static_assert(kMaxRosRootName + std::string_view("/s_").size() + 20 + 1 + kMaxIdentifier <= kMaxRosName,
              "a session's ROS name (root, /s_, a 64-bit id, _, host id) must fit sim_rfb's limit");

/// The longest rosbridge URL, characters.
constexpr std::size_t kMaxWebSocketUrl = 2048;

/// True for 1..kMaxIdentifier letters, digits, '-' and '_': safe in file names, paths, logs, command lines and
/// the HUD.
bool is_identifier(std::string_view text);

/// True for a ROS graph name of at most `max_size` characters: '/', then one or more segments of [A-Za-z0-9_]
/// that start with a letter, joined by single '/', with no trailing '/'. E.g. "/rfbsim/s_12".
bool is_ros_name(std::string_view name, std::size_t max_size = kMaxRosName);

/// Why `url` cannot be a rosbridge server to dial ("" when it can): ws:// or wss://, then a host (and optional
/// port and path) of visible ASCII with no user info, query or fragment (a URL shows in `ps`, logs, the admin
/// page and session.json; credentials belong in a token file), at most kMaxWebSocketUrl characters.
std::string websocket_url_problem(std::string_view url);

/// True for "*" or the shape of an origin, http:// or https:// then a non-empty authority with no '/', '?',
/// '#', '@' or space: what sim_rfb's --allow-origin takes (librfbsim parses host and port when it starts).
bool looks_like_origin(std::string_view text);

/// True for an origin exactly as browsers send it, so that it can be compared byte for byte with an Origin
/// header: http:// or https:// then lower-case letters, digits, '.', '-', ':', '[' and ']' (sim_manager's
/// frame_origins). Every such origin also looks_like_origin.
bool is_browser_origin(std::string_view text);

}  // namespace rfbsim::contract
