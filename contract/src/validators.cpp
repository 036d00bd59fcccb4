// SPDX-License-Identifier: GPL-2.0-or-later
// The validators both sim_manager and sim_rfb apply to the values they pass between them.
#include "contract/validators.hpp"

#include <algorithm>
#include <optional>

namespace rfbsim::contract {

namespace {

bool is_ascii_letter(char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z'); }
bool is_ascii_digit(char ch) { return ch >= '0' && ch <= '9'; }
// Visible ASCII: no space, control character, DEL or byte above 0x7f.
bool is_visible_ascii(char ch) { return ch > ' ' && ch < 0x7f; }

// `text` without its leading "http://" or "https://"; nullopt when it has neither.
std::optional<std::string_view> after_web_scheme(std::string_view text) {
  for (const std::string_view scheme : {std::string_view("http://"), std::string_view("https://")}) {
    if (text.substr(0, scheme.size()) == scheme) return text.substr(scheme.size());
  }
  return std::nullopt;
}

}  // namespace

bool is_identifier(std::string_view text) {
  if (text.empty() || text.size() > kMaxIdentifier) return false;
  return std::all_of(text.begin(), text.end(),
                     [](char ch) { return is_ascii_letter(ch) || is_ascii_digit(ch) || ch == '-' || ch == '_'; });
}

bool is_ros_name(std::string_view name, std::size_t max_size) {
  if (name.size() < 2 || name.size() > max_size || name.front() != '/' || name.back() == '/') return false;
  bool segment_start = true;
  for (std::size_t i = 1; i < name.size(); ++i) {
    const char ch = name[i];
    if (ch == '/') {
      if (segment_start) return false;  // "//": an empty segment
      segment_start = true;
      continue;
    }
    if (segment_start ? !is_ascii_letter(ch) : !(is_ascii_letter(ch) || is_ascii_digit(ch) || ch == '_')) return false;
    segment_start = false;
  }
  return true;
}

std::string websocket_url_problem(std::string_view url) {
  if (url.size() > kMaxWebSocketUrl) return "is longer than " + std::to_string(kMaxWebSocketUrl) + " characters";
  std::string_view rest = url;
  if (rest.substr(0, 6) == "wss://") {
    rest.remove_prefix(6);
  } else if (rest.substr(0, 5) == "ws://") {
    rest.remove_prefix(5);
  } else {
    return "expected a ws:// or wss:// URL such as wss://ros.lab.example.org:9090/";
  }
  if (!std::all_of(url.begin(), url.end(), is_visible_ascii)) return "must not hold spaces or control characters";
  const std::string_view authority = rest.substr(0, rest.find_first_of("/?#"));
  if (authority.empty() || authority.front() == ':') return "has no host";
  if (authority.find('@') != std::string_view::npos) {
    return "must not hold user info (user@host): put the credential in token_file";
  }
  // Sessions log the URL and record it in session.json: a query or fragment could carry a credential.
  if (url.find_first_of("?#") != std::string_view::npos) {
    return "must not hold a query or fragment: put a credential in token_file";
  }
  return "";
}

bool looks_like_origin(std::string_view text) {
  if (text == "*") return true;
  const auto authority = after_web_scheme(text);
  return authority && !authority->empty() && authority->find_first_of("/?#@ ") == std::string_view::npos;
}

bool is_browser_origin(std::string_view text) {
  const auto authority = after_web_scheme(text);
  if (!authority || !looks_like_origin(text)) return false;
  // Upper case, paths, queries, user info: not an origin as browsers send it.
  return std::all_of(authority->begin(), authority->end(), [](char ch) {
    return (ch >= 'a' && ch <= 'z') || is_ascii_digit(ch) || ch == '.' || ch == '-' || ch == ':' || ch == '[' ||
           ch == ']';
  });
}

}  // namespace rfbsim::contract
