// SPDX-License-Identifier: GPL-2.0-or-later
// Slow peers: a client that dribbles one RFB message a byte at a time. libvncserver reads a message
// with rfbReadExact, which waits up to maxClientWait for EACH next byte, on the server's only network
// thread; without a bound on the whole message, no other client would be read from or written to
// while it dribbles. ServerOptions::read_timeout is that bound.
#include <catch2/catch.hpp>

#include <atomic>
#include <thread>

#include "misbehaving_clients.hpp"
#include "served_scene.hpp"

namespace {

using namespace std::chrono_literals;
using rfbsim::test::Clock;
using rfbsim::test::RawSocket;
using rfbsim::test::ServedScene;

}  // namespace

TEST_CASE("a client dribbling one message byte by byte does not starve the others", "[robustness][slow][busy]") {
  rfbsim::ServerOptions options;
  options.width = 160;
  options.height = 120;
  options.read_timeout = 1000ms;
  ServedScene scene(options);

  // After a proper handshake: a SetEncodings header announcing 1000 encodings (4000 bytes follow),
  // then one byte every 300 ms, always inside the server's 1 s wait for the next byte.
  RawSocket slow(scene.port());
  rfbsim::test::raw_rfb_handshake(slow);
  REQUIRE(slow.send_all(std::vector<std::uint8_t>{2, 0, 0x03, 0xe8}));
  std::atomic<bool> stop{false};
  std::thread dribbler([&] {
    while (!stop) {
      std::this_thread::sleep_for(300ms);
      if (!slow.send_all(std::string_view("\0", 1))) return;
    }
  });

  // Over the next ten seconds the good client should see several fresh frames.
  int fresh = 0;
  const auto until = Clock::now() + 10s;
  while (Clock::now() < until) {
    if (scene.good_client_gets_fresh_frame(2s)) ++fresh;
  }
  stop = true;
  dribbler.join();
  CHECK(fresh >= 3);
  CHECK(scene.server().stats().stalled_clients_dropped >= 1);
  slow.close();
  scene.check_still_serving();
}
