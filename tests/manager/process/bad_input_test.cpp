// SPDX-License-Identifier: GPL-2.0-or-later
// Bad input against a real sim_manager: every /start parameter malformed in turn, path traversal, oversized
// URLs and headers, garbage, WebSockets to unknown or ended sessions or from other origins, unsigned and
// wrongly signed links. Each gets a 4xx with a clear message, and the manager goes on serving.
#include <catch2/catch.hpp>

#include <openssl/evp.h>
#include <openssl/hmac.h>

#include <algorithm>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::WsRfbBridge;
using rfbsim::test::token_from_redirect;
namespace net = rfbsim::test::net;

namespace {

constexpr const char* kSecret = "test-link-secret-0123456789";

// The manager still answers a valid link and its health check.
void check_still_serving(ManagerUnderTest& manager, const std::string& uid) {
  CHECK(manager.get("/healthz").status == 200);
  CHECK(manager.start("uid=" + uid).status == 302);
}

// The test's own HMAC-SHA256 of a link's canonical text (sorted name=value pairs, '&'-joined).
std::string sign(std::vector<std::pair<std::string, std::string>> params) {
  std::sort(params.begin(), params.end());
  std::string text;
  for (const auto& [name, value] : params) text += (text.empty() ? "" : "&") + name + "=" + value;
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  HMAC(EVP_sha256(), kSecret, static_cast<int>(std::string(kSecret).size()),
       reinterpret_cast<const unsigned char*>(text.data()), text.size(), digest, &length);
  std::string hex;
  char byte[3];
  for (unsigned int i = 0; i < length; ++i) {
    std::snprintf(byte, sizeof byte, "%02x", digest[i]);
    hex += byte;
  }
  return hex;
}

}  // namespace

TEST_CASE("every malformed /start parameter gets a 400 that names it, and the manager serves on", "[manager]") {
  TempDir data;
  // Many requests from loopback on purpose: the abuse limits would answer 429 before the parser is reached.
  ManagerUnderTest manager(data.path(), rfbsim::test::without_abuse_limits(rfbsim::test::small_session_args()));
  struct Case {
    const char* query;
    const char* says;
  };
  const Case cases[] = {
      {"scenario=lab", "no uid"},
      {"uid=", "uid '' is not valid"},
      {"uid=a/b", "uid 'a/b' is not valid"},
      {"uid=..%2F..%2Fetc", "is not valid"},
      {"uid=%2e%2e", "is not valid"},
      {"uid=aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa", "is not valid"},  // 65
      {"uid=p1&scenario=../../etc/passwd", "is not offered here"},
      {"uid=p1&scenario=office", "is not offered here"},
      // A spawn name the scenario lacks: refused here, not a session that would fail to start.
      {"uid=p1&scenario=lab&avatar_start=nowhere", "is not a spawn point of lab"},
      {"uid=p1&seed=-1", "seed '-1' is not valid"},
      {"uid=p1&seed=1e3", "seed '1e3' is not valid"},
      {"uid=p1&seed=18446744073709551616", "is not valid"},
      {"uid=p1&avatar_start=1,2", "avatar_start '1,2' is not valid"},
      {"uid=p1&avatar_goal=1,2,3,4", "is not valid"},
      {"uid=p1&robot_start=nan,0,0", "is not valid"},
      {"uid=p1&robot_goal=1e9,0,0", "is not valid"},
      {"uid=p1&crowd=501", "crowd '501' is not valid"},
      {"uid=p1&crowd=many", "is not valid"},
      {"uid=p1&colour=red", "unknown parameter 'colour'"},
      {"uid=p1&uid=p2", "given twice"},
      {"uid=p1&%zz=1", "bad percent-encoding"},
      {"uid=p1%0a", "bad percent-encoding"},
      {"uid=p1&&scenario=lab", "malformed parameter"},
      {"uid", "malformed parameter"},
  };
  for (const Case& c : cases) {
    INFO("query: " << c.query);
    const auto response = manager.start(c.query);
    CHECK(response.status == 400);
    // The page escapes what it quotes: ' is &#39; in the HTML.
    std::string says = c.says;
    for (std::size_t at = says.find('\''); at != std::string::npos; at = says.find('\'', at + 5)) {
      says.replace(at, 1, "&#39;");
    }
    CHECK(response.body.find(says) != std::string::npos);
    CHECK(response.headers.at("content-type") == "text/html; charset=utf-8");
  }
  CHECK(manager.index_rows().empty());  // nothing was started
  CHECK(manager.metric("rfbsim_rejections_total{reason=\"bad_request\"}") == static_cast<double>(std::size(cases)));
  check_still_serving(manager, "after-bad-params");
}

TEST_CASE("paths, methods, sizes and garbage outside the protocol get a 4xx, and the manager serves on",
          "[manager]") {
  TempDir data;
  // Many requests from loopback on purpose: the abuse limits would answer 429 before the parser is reached.
  ManagerUnderTest manager(data.path(), rfbsim::test::without_abuse_limits(rfbsim::test::small_session_args()));
  const std::string token = token_from_redirect(manager.start("uid=victim"));
  REQUIRE(manager.wait_for_state(token, "running"));

  SECTION("path traversal under a session stays in the page's folder") {
    for (const std::string& path : {"/s/" + token + "/../../../etc/passwd", "/s/" + token + "/%2e%2e/%2e%2e/etc/passwd",
                                   "/s/" + token + "/..%2f..%2fetc%2fpasswd", "/s/" + token + "/novnc/../../x"}) {
      INFO(path);
      const auto response = manager.get(path);
      CHECK(response.status == 404);
      CHECK(response.body.find("root:") == std::string::npos);
    }
    CHECK(manager.get("/s/" + token + "/app.js").status == 200);
  }
  SECTION("unknown tokens and addresses") {
    CHECK(manager.get("/s/0123456789abcdef0123456789abcdef/").status == 404);
    CHECK(manager.get("/s/not-a-token/").status == 404);
    CHECK(manager.get("/s/" + token).status == 404);
    CHECK(manager.get("/etc/passwd").status == 404);
    CHECK(manager.get("/s/" + token + "/ws").status == 400);  // a WebSocket address, asked for as a page
  }
  SECTION("methods") {
    const auto post = net::http_request(manager.port(),
                                        "POST /start?uid=x HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 0\r\n\r\n");
    CHECK(post.status == 405);
    CHECK(post.headers.at("allow") == "GET, HEAD");
  }
  SECTION("an oversized URL") {
    const auto response = manager.get("/start?uid=p1&pad=" + std::string(5000, 'x'));
    CHECK(response.status == 414);
  }
  SECTION("oversized headers") {
    const auto response = manager.get("/healthz", {{"X-Padding", std::string(20000, 'y')}});
    CHECK(response.status == 431);
  }
  SECTION("garbage instead of HTTP") {
    const auto response = net::http_request(manager.port(), "HELLO THERE\r\n\r\n");
    CHECK(response.status == 400);
    const auto binary = net::http_request(manager.port(), std::string("\x16\x03\x01\x00\x05hello", 10), false, 2s);
    CHECK((binary.status == 400 || binary.status == -1));
  }
  SECTION("a WebSocket to an unknown session, from a foreign origin, or to the wrong address") {
    {
      WsRfbBridge bridge(manager.ws_url("0123456789abcdef0123456789abcdef"));
      CHECK_THROWS(RfbTestClient("127.0.0.1", bridge.port()));
      REQUIRE(bridge.wait_last_finished(5s));
      CHECK(bridge.last_handshake_status() == 404);
    }
    {
      WsRfbBridge bridge(manager.ws_url(token), "https://evil.example");
      CHECK_THROWS(RfbTestClient("127.0.0.1", bridge.port()));
      REQUIRE(bridge.wait_last_finished(5s));
      CHECK(bridge.last_handshake_status() == 403);
    }
    {
      WsRfbBridge bridge("ws://127.0.0.1:" + std::to_string(manager.port()) + "/start");
      CHECK_THROWS(RfbTestClient("127.0.0.1", bridge.port()));
      REQUIRE(bridge.wait_last_finished(5s));
      CHECK(bridge.last_handshake_status() == 404);
    }
    // The manager's own origin is welcome.
    WsRfbBridge own(manager.ws_url(token), manager.origin());
    RfbTestClient client("127.0.0.1", own.port());
    CHECK(client.wait_for_updates(1, 20s));
    CHECK(manager.metric("rfbsim_rejections_total{reason=\"forbidden_origin\"}") == 1);
  }
  check_still_serving(manager, "after-garbage");
  CHECK(manager.state_of(token) == "running");
}

TEST_CASE("with a link secret only correctly signed links start sessions", "[manager]") {
  TempDir data;
  ManagerUnderTest manager(data.path(), {"--link-secret", kSecret, "--scenarios", "lab"});
  const std::string good_sig = sign({{"uid", "signed-1"}, {"scenario", "lab"}});

  const auto unsigned_link = manager.start("uid=signed-1&scenario=lab");
  CHECK(unsigned_link.status == 403);
  CHECK(unsigned_link.body.find("signature") != std::string::npos);
  CHECK(manager.start("uid=signed-1&scenario=lab&sig=" + std::string(64, '0')).status == 403);
  CHECK(manager.start("uid=signed-2&scenario=lab&sig=" + good_sig).status == 403);  // another uid
  CHECK(manager.start("uid=signed-1&scenario=lab&seed=7&sig=" + good_sig).status == 403);  // a parameter added
  CHECK(manager.metric("rfbsim_rejections_total{reason=\"bad_signature\"}") == 4);
  CHECK(manager.index_rows().empty());

  // The order of the parameters does not matter; the manager's own --sign agrees with this test's HMAC.
  CHECK(manager.start("scenario=lab&sig=" + good_sig + "&uid=signed-1").status == 302);
  const auto signed_by_tool = rfbsim::test::run_to_exit(
      rfbsim::test::sim_manager_path(), {"--link-secret", kSecret, "--sign", "uid=signed-1&scenario=lab"});
  CHECK(signed_by_tool.output == "uid=signed-1&scenario=lab&sig=" + good_sig + "\n");
}
