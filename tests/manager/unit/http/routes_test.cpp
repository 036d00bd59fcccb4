// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "http/routes.hpp"

using rfbsim::manager::is_token;
using rfbsim::manager::route_request;
using rfbsim::manager::RouteKind;

namespace {

const std::string kToken = "0123456789abcdef0123456789abcdef";

RouteKind kind(std::string_view method, std::string_view target) { return route_request(method, target).kind; }

}  // namespace

TEST_CASE("the fixed paths route to their handlers") {
  CHECK(kind("GET", "/") == RouteKind::kHome);
  CHECK(kind("GET", "/start") == RouteKind::kStart);
  CHECK(kind("GET", "/healthz") == RouteKind::kHealth);
  CHECK(kind("GET", "/metrics") == RouteKind::kMetrics);
  CHECK(kind("GET", "/api/sessions") == RouteKind::kApiSessions);
}

TEST_CASE("HEAD is taken wherever GET is") {
  CHECK(kind("HEAD", "/") == RouteKind::kHome);
  CHECK(kind("HEAD", "/start") == RouteKind::kStart);
  CHECK(kind("HEAD", "/s/" + kToken + "/") == RouteKind::kSessionFile);
  CHECK(kind("HEAD", "/api/sessions/3/end") == RouteKind::kBadMethod);
}

TEST_CASE("the admin page and its files") {
  const auto bare = route_request("GET", "/admin");
  CHECK(bare.kind == RouteKind::kAdminPage);
  CHECK(bare.file.empty());
  const auto slash = route_request("GET", "/admin/");
  CHECK(slash.kind == RouteKind::kAdminPage);
  CHECK(slash.file.empty());
  const auto script = route_request("GET", "/admin/admin.js?v=2");
  CHECK(script.kind == RouteKind::kAdminPage);
  CHECK(script.file == "admin.js");
  CHECK(script.query == "v=2");
  CHECK(kind("GET", "/administrator") == RouteKind::kNotFound);
  CHECK(kind("POST", "/admin") == RouteKind::kBadMethod);
}

TEST_CASE("a known path with the wrong method is a bad method") {
  CHECK(kind("POST", "/start") == RouteKind::kBadMethod);
  CHECK(kind("PUT", "/") == RouteKind::kBadMethod);
  CHECK(kind("DELETE", "/api/sessions") == RouteKind::kBadMethod);
  CHECK(kind("POST", "/healthz") == RouteKind::kBadMethod);
  CHECK(kind("POST", "/metrics") == RouteKind::kBadMethod);
  CHECK(kind("GET", "/api/sessions/3/end") == RouteKind::kBadMethod);
  CHECK(kind("POST", "/s/" + kToken + "/ws") == RouteKind::kBadMethod);
  CHECK(kind("get", "/") == RouteKind::kBadMethod);  // methods are case-sensitive
}

TEST_CASE("an unknown path is not found whatever the method") {
  CHECK(kind("GET", "/nothing") == RouteKind::kNotFound);
  CHECK(kind("POST", "/nothing") == RouteKind::kNotFound);
  CHECK(kind("GET", "") == RouteKind::kNotFound);
  CHECK(kind("GET", "/start/") == RouteKind::kNotFound);
  CHECK(kind("GET", "//") == RouteKind::kNotFound);
}

TEST_CASE("ending a session takes a positive decimal id") {
  const auto route = route_request("POST", "/api/sessions/3/end");
  CHECK(route.kind == RouteKind::kApiEndSession);
  CHECK(route.session_id == 3);
  CHECK(route_request("POST", "/api/sessions/9223372036854775807/end").session_id == 9223372036854775807LL);
  CHECK(kind("POST", "/api/sessions/0/end") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/-3/end") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/+3/end") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/x/end") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/3x/end") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/ 3/end") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions//end") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/9223372036854775808/end") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/3") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/3/end/") == RouteKind::kNotFound);
  CHECK(kind("POST", "/api/sessions/3/stop") == RouteKind::kNotFound);
}

TEST_CASE("session paths carry a token and what lies below it") {
  SECTION("the page") {
    const auto route = route_request("GET", "/s/" + kToken + "/");
    CHECK(route.kind == RouteKind::kSessionFile);
    CHECK(route.token == kToken);
    CHECK(route.file.empty());
  }
  SECTION("a nested file") {
    const auto route = route_request("GET", "/s/" + kToken + "/novnc/core/rfb.js");
    CHECK(route.kind == RouteKind::kSessionFile);
    CHECK(route.token == kToken);
    CHECK(route.file == "novnc/core/rfb.js");
  }
  SECTION("the file is not decoded") {
    CHECK(route_request("GET", "/s/" + kToken + "/a%20b.js").file == "a%20b.js");
  }
  SECTION("status") {
    const auto route = route_request("GET", "/s/" + kToken + "/status");
    CHECK(route.kind == RouteKind::kSessionStatus);
    CHECK(route.token == kToken);
  }
  SECTION("the WebSocket") {
    const auto route = route_request("GET", "/s/" + kToken + "/ws");
    CHECK(route.kind == RouteKind::kSessionSocket);
    CHECK(route.token == kToken);
  }
  SECTION("ws and status only as the whole rest") {
    CHECK(kind("GET", "/s/" + kToken + "/ws/") == RouteKind::kSessionFile);
    CHECK(kind("GET", "/s/" + kToken + "/status.json") == RouteKind::kSessionFile);
  }
}

TEST_CASE("session paths without a valid token are not found") {
  CHECK(kind("GET", "/s/" + kToken) == RouteKind::kNotFound);  // no trailing slash
  CHECK(kind("GET", "/s/") == RouteKind::kNotFound);
  CHECK(kind("GET", "/s//") == RouteKind::kNotFound);
  CHECK(kind("GET", "/s/" + kToken.substr(1) + "/") == RouteKind::kNotFound);
  CHECK(kind("GET", "/s/" + kToken + "0/") == RouteKind::kNotFound);
  CHECK(kind("GET", "/s/0123456789ABCDEF0123456789abcdef/") == RouteKind::kNotFound);
  CHECK(kind("GET", "/s/0123456789abcdeg0123456789abcdef/ws") == RouteKind::kNotFound);
}

TEST_CASE("the query string is kept raw") {
  const auto route = route_request("GET", "/start?uid=p%2001&scenario=lab");
  CHECK(route.kind == RouteKind::kStart);
  CHECK(route.query == "uid=p%2001&scenario=lab");
  CHECK(route_request("GET", "/start").query.empty());
  CHECK(route_request("GET", "/nothing?a=1").query == "a=1");
  const auto ws = route_request("GET", "/s/" + kToken + "/ws?x=1");
  CHECK(ws.kind == RouteKind::kSessionSocket);
  CHECK(ws.query == "x=1");
}

TEST_CASE("a token is 32 lower-case hex digits") {
  CHECK(is_token(kToken));
  CHECK(is_token(std::string(32, 'f')));
  CHECK_FALSE(is_token(""));
  CHECK_FALSE(is_token(kToken.substr(0, 31)));
  CHECK_FALSE(is_token(kToken + "0"));
  CHECK_FALSE(is_token("0123456789ABCDEF0123456789abcdef"));
  CHECK_FALSE(is_token("0123456789abcdeg0123456789abcdef"));
  CHECK_FALSE(is_token("0123456789abcde-0123456789abcdef"));
}

TEST_CASE("a path asked for with the wrong method says which methods it takes") {
  CHECK(std::string(route_request("POST", "/start").allowed) == "GET, HEAD");
  CHECK(std::string(route_request("GET", "/api/sessions/3/end").allowed) == "POST");
  CHECK(std::string(route_request("DELETE", "/s/" + kToken + "/").allowed) == "GET, HEAD");
}

TEST_CASE("watch paths carry a token and what lies below it, like session paths") {
  SECTION("the page") {
    const auto route = route_request("GET", "/admin/watch/" + kToken + "/");
    CHECK(route.kind == RouteKind::kWatchFile);
    CHECK(route.token == kToken);
    CHECK(route.file.empty());
  }
  SECTION("its files") {
    const auto bundle = route_request("GET", "/admin/watch/" + kToken + "/app.bundle.js");
    CHECK(bundle.kind == RouteKind::kWatchFile);
    CHECK(bundle.token == kToken);
    CHECK(bundle.file == "app.bundle.js");
    CHECK(route_request("GET", "/admin/watch/" + kToken + "/novnc/core/rfb.js").file == "novnc/core/rfb.js");
  }
  SECTION("status") {
    const auto route = route_request("GET", "/admin/watch/" + kToken + "/status");
    CHECK(route.kind == RouteKind::kWatchStatus);
    CHECK(route.token == kToken);
  }
  SECTION("the WebSocket, with its query kept raw") {
    const auto route = route_request("GET", "/admin/watch/" + kToken + "/ws?x=1");
    CHECK(route.kind == RouteKind::kWatchSocket);
    CHECK(route.token == kToken);
    CHECK(route.query == "x=1");
  }
  SECTION("ws and status only as the whole rest") {
    CHECK(kind("GET", "/admin/watch/" + kToken + "/ws/") == RouteKind::kWatchFile);
    CHECK(kind("GET", "/admin/watch/" + kToken + "/status.json") == RouteKind::kWatchFile);
  }
  SECTION("HEAD as GET; other methods are refused") {
    CHECK(kind("HEAD", "/admin/watch/" + kToken + "/") == RouteKind::kWatchFile);
    const auto post = route_request("POST", "/admin/watch/" + kToken + "/ws");
    CHECK(post.kind == RouteKind::kBadMethod);
    CHECK(std::string(post.allowed) == "GET, HEAD");
  }
}

TEST_CASE("watch paths without a valid token are not found, and never the admin page") {
  CHECK(kind("GET", "/admin/watch/" + kToken) == RouteKind::kNotFound);  // no trailing slash
  CHECK(kind("GET", "/admin/watch/") == RouteKind::kNotFound);
  CHECK(kind("GET", "/admin/watch//ws") == RouteKind::kNotFound);
  CHECK(kind("GET", "/admin/watch/" + kToken.substr(1) + "/") == RouteKind::kNotFound);
  CHECK(kind("GET", "/admin/watch/0123456789ABCDEF0123456789abcdef/ws") == RouteKind::kNotFound);
  CHECK(kind("GET", "/admin/watch/../s/" + kToken + "/ws") == RouteKind::kNotFound);
  // Only /admin/watch/ itself leads there: the admin page's own files and the participant's paths stay apart.
  CHECK(kind("GET", "/admin/watch") == RouteKind::kAdminPage);
  CHECK(kind("GET", "/admin/watching/" + kToken + "/") == RouteKind::kAdminPage);
  CHECK(kind("GET", "/s/" + kToken + "/admin/watch/" + kToken + "/ws") == RouteKind::kSessionFile);
}

TEST_CASE("a path under the manager's prefix routes as the path without it") {
  const auto page = route_request("GET", "/h2/s/" + kToken + "/", "/h2");
  CHECK(page.kind == RouteKind::kSessionFile);
  CHECK(page.token == kToken);
  CHECK(page.file.empty());
  CHECK(kind("GET", "/h2/s/" + kToken + "/status") == RouteKind::kNotFound);  // no prefix configured
  CHECK(route_request("GET", "/h2/s/" + kToken + "/status", "/h2").kind == RouteKind::kSessionStatus);
  const auto ws = route_request("GET", "/h2/s/" + kToken + "/ws?x=1", "/h2");
  CHECK(ws.kind == RouteKind::kSessionSocket);
  CHECK(ws.query == "x=1");
  CHECK(route_request("GET", "/h2/admin/watch/" + kToken + "/ws", "/h2").kind == RouteKind::kWatchSocket);
  CHECK(route_request("GET", "/h2/admin", "/h2").kind == RouteKind::kAdminPage);
  CHECK(route_request("GET", "/h2/admin/admin.js", "/h2").file == "admin.js");
  CHECK(route_request("GET", "/h2/api/sessions", "/h2").kind == RouteKind::kApiSessions);
  CHECK(route_request("POST", "/h2/api/sessions/7/end", "/h2").session_id == 7);
  CHECK(route_request("GET", "/h2/start?uid=a", "/h2").kind == RouteKind::kStart);
  CHECK(route_request("GET", "/h2/start?uid=a", "/h2").query == "uid=a");
  CHECK(route_request("GET", "/h2", "/h2").kind == RouteKind::kHome);
  CHECK(route_request("GET", "/h2/", "/h2").kind == RouteKind::kHome);
}

TEST_CASE("the balancer's unprefixed paths still route under a prefix") {
  CHECK(route_request("GET", "/start?uid=a", "/h2").kind == RouteKind::kStart);
  CHECK(route_request("GET", "/healthz", "/h2").kind == RouteKind::kHealth);
  CHECK(route_request("GET", "/s/" + kToken + "/", "/h2").kind == RouteKind::kSessionFile);
}

TEST_CASE("a prefix ends at a path segment and is stripped once") {
  CHECK(route_request("GET", "/h2x/start", "/h2").kind == RouteKind::kNotFound);
  CHECK(route_request("GET", "/h20/healthz", "/h2").kind == RouteKind::kNotFound);
  CHECK(route_request("GET", "/h2/h2/start", "/h2").kind == RouteKind::kNotFound);
  CHECK(route_request("GET", "/h1/start", "/h2").kind == RouteKind::kNotFound);  // another host's prefix
  CHECK(rfbsim::manager::strip_path_prefix("/h2/a", "/h2") == "/a");
  CHECK(rfbsim::manager::strip_path_prefix("/h2", "/h2") == "/");
  CHECK(rfbsim::manager::strip_path_prefix("/h2a", "/h2") == "/h2a");
  CHECK(rfbsim::manager::strip_path_prefix("/a", "") == "/a");
}

TEST_CASE("drain, undrain, host and cluster are admin API paths") {
  CHECK(kind("POST", "/api/drain") == RouteKind::kApiDrain);
  CHECK(kind("POST", "/api/undrain") == RouteKind::kApiUndrain);
  CHECK(kind("GET", "/api/host") == RouteKind::kApiHost);
  CHECK(kind("GET", "/api/cluster") == RouteKind::kApiCluster);
  CHECK(route_request("POST", "/h3/api/drain", "/h3").kind == RouteKind::kApiDrain);
  // Drain changes state: GET (a prefetch, a crawler following a link) must not do it.
  CHECK(kind("GET", "/api/drain") == RouteKind::kBadMethod);
  CHECK(std::string(route_request("GET", "/api/undrain").allowed) == "POST");
  CHECK(kind("POST", "/api/host") == RouteKind::kBadMethod);
  CHECK(kind("GET", "/api/drain/") == RouteKind::kNotFound);
}

TEST_CASE("a path prefix is a slash and 1 to 32 of a-z, 0-9 and -") {
  using rfbsim::manager::is_path_prefix;
  CHECK(is_path_prefix("/h2"));
  CHECK(is_path_prefix("/a"));
  CHECK(is_path_prefix("/" + std::string(32, 'z')));
  CHECK(is_path_prefix("/host-0"));
  CHECK_FALSE(is_path_prefix(""));
  CHECK_FALSE(is_path_prefix("/"));
  CHECK_FALSE(is_path_prefix("h2"));
  CHECK_FALSE(is_path_prefix("/h2/"));
  CHECK_FALSE(is_path_prefix("/H2"));
  CHECK_FALSE(is_path_prefix("/h_2"));
  CHECK_FALSE(is_path_prefix("/a/b"));
  CHECK_FALSE(is_path_prefix("/" + std::string(33, 'z')));
}
