// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager over TLS: HTTPS links and pages and a WSS relay to a real session, with a certificate made
// during the test; plain HTTP on the TLS port gets nothing; a bad certificate stops the manager at start.
#include <catch2/catch.hpp>

#include <fstream>
#include <sys/wait.h>

#include "manager_process.hpp"
#include "rfb_test_client.hpp"
#include "tls_test_cert.hpp"
#include "ws_rfb_bridge.hpp"

using namespace std::chrono_literals;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::RfbTestClient;
using rfbsim::test::TempDir;
using rfbsim::test::WsRfbBridge;
using rfbsim::test::token_from_redirect;

TEST_CASE("https and wss with a certificate made for the test", "[manager][tls]") {
  TempDir data;
  const auto certificate = rfbsim::test::make_test_certificate(data.path());
  ManagerUnderTest manager(data.path() / "data",
                           rfbsim::test::with_small_sessions({"--tls-certificate", certificate.cert_pem.string(),
                                                              "--tls-private-key", certificate.key_pem.string()}));

  CHECK(manager.get("/healthz", {}, true).status == 200);
  CHECK(manager.get("/healthz", {}, false).status == -1);  // plain HTTP on a TLS port gets no answer
  const auto start = manager.start("uid=tls-1", true);
  REQUIRE(start.status == 302);
  const std::string token = token_from_redirect(start);
  REQUIRE(token.size() == 32);
  CHECK(manager.get("/s/" + token + "/", {}, true).status == 200);

  rfbsim::test::WsRfbBridgeOptions options;
  options.verify_certificate = true;
  options.ca_file = certificate.cert_pem.string();
  WsRfbBridge bridge(manager.ws_url(token, true), options);
  RfbTestClient client("127.0.0.1", bridge.port());
  CHECK(client.wait_for_updates(1, 20s));
  CHECK(manager.wait_for_state(token, "running", 5s, true));
}

TEST_CASE("a certificate that cannot be loaded stops the manager at start with the file named", "[manager][tls]") {
  TempDir data;
  const auto certificate = rfbsim::test::make_test_certificate(data.path());
  std::ofstream(data.path() / "broken.pem") << "-----BEGIN CERTIFICATE-----\nnot base64\n";
  const auto result = rfbsim::test::run_to_exit(
      rfbsim::test::sim_manager_path(),
      {"--port", "0", "--data-dir", (data.path() / "data").string(), "--tls-certificate",
       (data.path() / "broken.pem").string(), "--tls-private-key", certificate.key_pem.string()});
  REQUIRE(WIFEXITED(result.status));
  CHECK(WEXITSTATUS(result.status) == 1);
  CHECK(result.output.find("broken.pem") != std::string::npos);

  const auto half = rfbsim::test::run_to_exit(rfbsim::test::sim_manager_path(),
                                              {"--port", "0", "--tls-certificate", certificate.cert_pem.string()});
  REQUIRE(WIFEXITED(half.status));
  CHECK(WEXITSTATUS(half.status) == 2);
  CHECK(half.output.find("both") != std::string::npos);
}
