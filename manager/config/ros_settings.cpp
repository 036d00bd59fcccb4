// SPDX-License-Identifier: GPL-2.0-or-later
// Checks of the `ros:` section and sessions' ROS names.
#include "config/ros_settings.hpp"

#include <filesystem>
#include <fstream>

namespace rfbsim::manager {

namespace {

constexpr std::size_t kMaxRosName = 200;
constexpr std::size_t kMaxUrl = 2048;
constexpr std::size_t kMaxToken = 4096;
// A CA bundle is kilobytes; anything far larger is the wrong file.
constexpr std::size_t kMaxCaFile = 4 * 1024 * 1024;

bool is_letter(char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z'); }
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

bool is_ros_name(std::string_view name) {
  if (name.size() < 2 || name.size() > kMaxRosName || name.front() != '/' || name.back() == '/') return false;
  bool segment_start = true;
  for (std::size_t i = 1; i < name.size(); ++i) {
    const char ch = name[i];
    if (ch == '/') {
      if (segment_start) return false;  // "//": an empty segment
      segment_start = true;
      continue;
    }
    if (segment_start ? !is_letter(ch) : !(is_letter(ch) || (ch >= '0' && ch <= '9') || ch == '_')) return false;
    segment_start = false;
  }
  return true;
}

std::string rosbridge_url_problem(std::string_view url) {
  if (url.size() > kMaxUrl) return "is longer than " + std::to_string(kMaxUrl) + " characters";
  std::string_view rest = url;
  if (rest.rfind("wss://", 0) == 0) {
    rest.remove_prefix(6);
  } else if (rest.rfind("ws://", 0) == 0) {
    rest.remove_prefix(5);
  } else {
    return "expected a ws:// or wss:// URL such as wss://ros.lab.example.org:9090/";
  }
  for (const char ch : url) {
    if (!is_visible(ch)) return "must not hold spaces or control characters";
  }
  const std::string_view authority = rest.substr(0, rest.find_first_of("/?#"));
  if (authority.empty() || authority.front() == ':') return "has no host";
  if (authority.find('@') != std::string_view::npos) {
    return "must not hold user info (user@host): put the credential in token_file";
  }
  // Sessions log the URL and record it in session.json: a query or fragment could carry a credential.
  if (url.find_first_of("?#") != std::string_view::npos) return "must not hold a query or fragment: put a credential in token_file";
  return "";
}

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
