// SPDX-License-Identifier: GPL-2.0-or-later
// Checks of the `ros:` section and sessions' ROS names.
#include "config/ros_settings.hpp"

#include <filesystem>
#include <fstream>

#include "contract/validators.hpp"

namespace rfbsim::manager {

namespace {

constexpr std::size_t kMaxToken = 4096;
// A CA bundle is kilobytes; anything far larger is the wrong file.
constexpr std::size_t kMaxCaFile = 4 * 1024 * 1024;

bool is_visible(char ch) { return ch > ' ' && ch < 0x7f; }

// The file's first `limit` + 1 bytes, so that an oversized file is seen as one; `ok` is false when it is not a
// regular file that can be opened (a folder opens, and would read as empty).
std::string read_head(const std::string& path, std::size_t limit, bool& ok) {
  std::error_code ec;
  std::ifstream in;
  if (std::filesystem::is_regular_file(path, ec)) in.open(path, std::ios::binary);
  ok = in.is_open() && static_cast<bool>(in);
  if (!ok) return "";
  std::string text(limit + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

}  // namespace

// The contract's rules (sim_rfb checks the same), with the root's own limit: room for each session's
// "/s_<id>_<host>" under sim_rfb's.
bool is_ros_name(std::string_view name) { return contract::is_ros_name(name, contract::kMaxRosRootName); }

std::string rosbridge_url_problem(std::string_view url) { return contract::websocket_url_problem(url); }

std::string token_file_problem(const std::string& path) {
  bool ok = false;
  std::string token = read_head(path, kMaxToken + 2, ok);
  if (!ok) return "cannot read " + path;
  // One line: a final "\n" or "\r\n" is the editor's, not the token's.
  if (!token.empty() && token.back() == '\n') token.pop_back();
  if (!token.empty() && token.back() == '\r') token.pop_back();
  if (token.empty()) return path + " is empty";
  if (token.size() > kMaxToken) return path + " holds more than " + std::to_string(kMaxToken) + " characters";
  for (const char ch : token) {
    if (!is_visible(ch)) return path + " must hold one token of visible ASCII (no spaces, lines or control characters)";
  }
  return "";
}

std::string ca_file_problem(const std::string& path) {
  bool ok = false;
  const std::string text = read_head(path, kMaxCaFile, ok);
  if (!ok) return "cannot read " + path;
  if (text.size() > kMaxCaFile) return path + " is larger than 4 MiB: not a CA bundle";
  if (text.find("-----BEGIN CERTIFICATE-----") == std::string::npos) {
    return path + " holds no PEM certificate (-----BEGIN CERTIFICATE-----)";
  }
  return "";
}

std::string ros_session_name(std::int64_t session_id, const std::string& cluster_host_id) {
  std::string name = "s_" + std::to_string(session_id);
  if (cluster_host_id.empty()) return name;
  name += '_';
  for (const char ch : cluster_host_id) name += ch == '-' ? '_' : ch;
  return name;
}

}  // namespace rfbsim::manager
