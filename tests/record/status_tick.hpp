// SPDX-License-Identifier: GPL-2.0-or-later
// The simulation tick a running sim_rfb reports on /status.json: the session's clock, which the recording tests
// read to check that a session goes on, and how far it got before a kill.
#pragma once

#include <catch2/catch.hpp>

#include <cstdint>
#include <nlohmann/json.hpp>

#include "http_client.hpp"

namespace rfbsim::test {

/// The tick of the sim_rfb serving /status.json on loopback `port`; fails the test if it does not answer 200.
inline std::uint64_t current_tick(int port) {
  const auto response = net::http_get(port, "/status.json");
  REQUIRE(response.status == 200);
  return nlohmann::json::parse(response.body)["tick"].get<std::uint64_t>();
}

}  // namespace rfbsim::test
