// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "http/web_policy.hpp"

using rfbsim::manager::admin_authorized;
using rfbsim::manager::Headers;
using rfbsim::manager::html_escape;
using rfbsim::manager::json_escape;
using rfbsim::manager::page_headers;
using rfbsim::manager::websocket_origin_allowed;

namespace {

const std::string kPolicyToken = "0123456789abcdef";
const std::vector<std::string> kFrameOrigins = {"https://a.example", "https://b.example"};

}  // namespace

TEST_CASE("page headers allow framing by the manager and the configured origins only") {
  CHECK(page_headers(kFrameOrigins) == Headers{
                                           {"Content-Security-Policy", "frame-ancestors 'self' https://a.example https://b.example"},
                                           {"Cache-Control", "no-store"},
                                           {"Referrer-Policy", "no-referrer"},
                                           {"X-Content-Type-Options", "nosniff"},
                                       });
  CHECK(page_headers({}).front() == Headers::value_type{"Content-Security-Policy", "frame-ancestors 'self'"});
}

TEST_CASE("a WebSocket without Origin or from the manager's own origin is allowed") {
  CHECK(websocket_origin_allowed("", "sim.example:8080", {}));
  CHECK(websocket_origin_allowed("http://sim.example:8080", "sim.example:8080", {}));
  CHECK(websocket_origin_allowed("https://sim.example:8080", "sim.example:8080", {}));
  CHECK(websocket_origin_allowed("https://sim.example", "sim.example", {}));
  CHECK(websocket_origin_allowed("http://127.0.0.1:8080", "127.0.0.1:8080", {}));
}

TEST_CASE("a WebSocket from a configured frame origin is allowed") {
  CHECK(websocket_origin_allowed("https://a.example", "sim.example", kFrameOrigins));
  CHECK(websocket_origin_allowed("https://b.example", "sim.example", kFrameOrigins));
  CHECK_FALSE(websocket_origin_allowed("http://a.example", "sim.example", kFrameOrigins));
  CHECK_FALSE(websocket_origin_allowed("https://a.example:444", "sim.example", kFrameOrigins));
}

TEST_CASE("a WebSocket from any other origin is refused") {
  CHECK_FALSE(websocket_origin_allowed("https://evil.example", "sim.example", kFrameOrigins));
  CHECK_FALSE(websocket_origin_allowed("null", "sim.example", kFrameOrigins));
  CHECK_FALSE(websocket_origin_allowed("http://sim.example:9090", "sim.example:8080", {}));
  CHECK_FALSE(websocket_origin_allowed("http://sim.example", "sim.example:8080", {}));
  CHECK_FALSE(websocket_origin_allowed("http://sim.example:8080", "sim.example", {}));
  CHECK_FALSE(websocket_origin_allowed("http://sim.example.evil.example", "sim.example", {}));
  CHECK_FALSE(websocket_origin_allowed("http://evil.example/sim.example", "sim.example", {}));
  CHECK_FALSE(websocket_origin_allowed("http://sim.example/", "sim.example", {}));
  CHECK_FALSE(websocket_origin_allowed("ftp://sim.example", "sim.example", {}));
  CHECK_FALSE(websocket_origin_allowed("sim.example", "sim.example", {}));
  CHECK_FALSE(websocket_origin_allowed("http://", "", {}));
  CHECK_FALSE(websocket_origin_allowed("https://a.example", "", {}));
}

TEST_CASE("the admin token is accepted as a Bearer token") {
  CHECK(admin_authorized("Bearer " + kPolicyToken, kPolicyToken));
  CHECK(admin_authorized("bearer " + kPolicyToken, kPolicyToken));
  CHECK(admin_authorized("BEARER " + kPolicyToken, kPolicyToken));
  CHECK_FALSE(admin_authorized("Bearer " + kPolicyToken + "x", kPolicyToken));
  CHECK_FALSE(admin_authorized("Bearer " + kPolicyToken.substr(1), kPolicyToken));
  CHECK_FALSE(admin_authorized("Bearer 0123456789ABCDEF", kPolicyToken));
  CHECK_FALSE(admin_authorized("Bearer  " + kPolicyToken, kPolicyToken));
  CHECK_FALSE(admin_authorized("Bearer", kPolicyToken));
  CHECK_FALSE(admin_authorized(kPolicyToken, kPolicyToken));
  CHECK_FALSE(admin_authorized("", kPolicyToken));
  CHECK_FALSE(admin_authorized("Token " + kPolicyToken, kPolicyToken));
}

TEST_CASE("the admin token is accepted as the password of HTTP Basic") {
  // base64("admin:0123456789abcdef"), base64(":0123456789abcdef"), base64("x:0123456789abcdef")
  CHECK(admin_authorized("Basic YWRtaW46MDEyMzQ1Njc4OWFiY2RlZg==", kPolicyToken));
  CHECK(admin_authorized("basic YWRtaW46MDEyMzQ1Njc4OWFiY2RlZg==", kPolicyToken));
  CHECK(admin_authorized("Basic OjAxMjM0NTY3ODlhYmNkZWY=", kPolicyToken));
  CHECK(admin_authorized("Basic eDowMTIzNDU2Nzg5YWJjZGVm", kPolicyToken));
}

TEST_CASE("HTTP Basic with a wrong or malformed credential is refused") {
  CHECK_FALSE(admin_authorized("Basic YWRtaW46MDEyMzQ1Njc4OWFiY2RlWA==", kPolicyToken));  // admin:0123456789abcdeX
  CHECK_FALSE(admin_authorized("Basic YWRtaW4wMTIzNDU2Nzg5YWJjZGVm", kPolicyToken));      // no colon
  CHECK_FALSE(admin_authorized("Basic !!!!", kPolicyToken));
  CHECK_FALSE(admin_authorized("Basic YWRtaW46MDEyMzQ1Njc4OWFiY2RlZg=", kPolicyToken));   // not a multiple of 4
  CHECK_FALSE(admin_authorized("Basic ", kPolicyToken));
  CHECK_FALSE(admin_authorized("Basic", kPolicyToken));
}

TEST_CASE("with no admin token configured nothing is authorized") {
  CHECK_FALSE(admin_authorized("Bearer ", ""));
  CHECK_FALSE(admin_authorized("", ""));
  CHECK_FALSE(admin_authorized("Basic Og==", ""));  // base64(":")
}

TEST_CASE("html_escape escapes the five special characters") {
  CHECK(html_escape("<a href=\"x\">'&'</a>") == "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
  CHECK(html_escape("plain text, \xC3\xA9") == "plain text, \xC3\xA9");
  CHECK(html_escape("").empty());
  CHECK(html_escape("&amp;") == "&amp;amp;");
}

TEST_CASE("json_escape escapes quotes, backslashes and control characters") {
  CHECK(json_escape("a\"b\\c") == "a\\\"b\\\\c");
  CHECK(json_escape("\n\r\t") == "\\n\\r\\t");
  CHECK(json_escape(std::string("\x01\x1f\0", 3)) == "\\u0001\\u001f\\u0000");
  CHECK(json_escape("</script> \xC3\xA9 \x7f") == "</script> \xC3\xA9 \x7f");
  CHECK(json_escape("").empty());
}
