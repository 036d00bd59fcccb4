// SPDX-License-Identifier: GPL-2.0-or-later
// Request routing for sim_manager.
#include "http/routes.hpp"

#include <charconv>

#include "http/query.hpp"

namespace rfbsim::manager {

namespace {

constexpr std::size_t kTokenLength = 32;

Route with_method(Route route, std::string_view method, std::string_view wanted) {
  if (method != wanted && !(wanted == "GET" && method == "HEAD")) {
    route.kind = RouteKind::kBadMethod;
    route.allowed = wanted == "GET" ? "GET, HEAD" : "POST";
  }
  return route;
}

// <token>/ and what lies below it, after /s/ or /admin/watch/: the page's files, its status and its socket.
Route token_route(Route route, std::string_view method, std::string_view rest, RouteKind file, RouteKind status,
                  RouteKind socket) {
  const std::size_t slash = rest.find('/');
  if (slash == std::string_view::npos || !is_token(rest.substr(0, slash))) return route;
  route.token = std::string(rest.substr(0, slash));
  const std::string_view below = rest.substr(slash + 1);
  if (below == "ws") {
    route.kind = socket;
  } else if (below == "status") {
    route.kind = status;
  } else {
    route.kind = file;
    route.file = std::string(below);
  }
  return with_method(route, method, "GET");
}

}  // namespace

bool is_token(std::string_view text) {
  if (text.size() != kTokenLength) return false;
  for (const char ch : text) {
    if (!((ch >= '0' && ch <= '9') || (ch >= 'a' && ch <= 'f'))) return false;
  }
  return true;
}

bool is_path_prefix(std::string_view text) {
  if (text.size() < 2 || text.size() > 33 || text.front() != '/') return false;
  for (const char ch : text.substr(1)) {
    if (!((ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '-')) return false;
  }
  return true;
}

std::string_view strip_path_prefix(std::string_view path, std::string_view path_prefix) {
  if (path_prefix.empty() || path.rfind(path_prefix, 0) != 0) return path;
  const std::string_view rest = path.substr(path_prefix.size());
  if (rest.empty()) return "/";
  // "/h2x/..." is not under "/h2": the prefix must end at a segment boundary.
  return rest.front() == '/' ? rest : path;
}

Route route_request(std::string_view method, std::string_view target, std::string_view path_prefix) {
  const auto [full_path, query] = split_target(target);
  const std::string_view path = strip_path_prefix(full_path, path_prefix);
  Route route;
  route.query = std::string(query);
  if (path == "/") {
    route.kind = RouteKind::kHome;
    return with_method(route, method, "GET");
  }
  if (path == "/start") {
    route.kind = RouteKind::kStart;
    return with_method(route, method, "GET");
  }
  if (path == "/healthz") {
    route.kind = RouteKind::kHealth;
    return with_method(route, method, "GET");
  }
  if (path == "/metrics") {
    route.kind = RouteKind::kMetrics;
    return with_method(route, method, "GET");
  }
  if (path == "/admin" || path == "/admin/") {
    route.kind = RouteKind::kAdminPage;
    return with_method(route, method, "GET");
  }
  // The researcher's view-only copy of a session's page; before /admin/'s own files, which it lies among.
  constexpr std::string_view kWatchPrefix = "/admin/watch/";
  if (path.rfind(kWatchPrefix, 0) == 0) {
    return token_route(route, method, path.substr(kWatchPrefix.size()), RouteKind::kWatchFile,
                       RouteKind::kWatchStatus, RouteKind::kWatchSocket);
  }
  if (path.rfind("/admin/", 0) == 0) {
    route.kind = RouteKind::kAdminPage;
    route.file = std::string(path.substr(7));
    return with_method(route, method, "GET");
  }
  if (path == "/api/sessions") {
    route.kind = RouteKind::kApiSessions;
    return with_method(route, method, "GET");
  }
  if (path == "/api/drain" || path == "/api/undrain") {
    route.kind = path == "/api/drain" ? RouteKind::kApiDrain : RouteKind::kApiUndrain;
    return with_method(route, method, "POST");
  }
  if (path == "/api/host" || path == "/api/cluster") {
    route.kind = path == "/api/host" ? RouteKind::kApiHost : RouteKind::kApiCluster;
    return with_method(route, method, "GET");
  }
  constexpr std::string_view kApiPrefix = "/api/sessions/";
  constexpr std::string_view kEndSuffix = "/end";
  if (path.rfind(kApiPrefix, 0) == 0 && path.size() > kApiPrefix.size() + kEndSuffix.size() &&
      path.substr(path.size() - kEndSuffix.size()) == kEndSuffix) {
    const std::string_view id = path.substr(kApiPrefix.size(), path.size() - kApiPrefix.size() - kEndSuffix.size());
    std::int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(id.data(), id.data() + id.size(), value);
    if (ec != std::errc() || ptr != id.data() + id.size() || value <= 0 || id.front() == '+') return route;
    route.kind = RouteKind::kApiEndSession;
    route.session_id = value;
    return with_method(route, method, "POST");
  }
  // /s/<token>/ and what lies below it.
  constexpr std::string_view kSessionPrefix = "/s/";
  if (path.rfind(kSessionPrefix, 0) == 0) {
    return token_route(route, method, path.substr(kSessionPrefix.size()), RouteKind::kSessionFile,
                       RouteKind::kSessionStatus, RouteKind::kSessionSocket);
  }
  return route;
}

}  // namespace rfbsim::manager
