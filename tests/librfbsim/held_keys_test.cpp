// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "held_keys.hpp"

using rfbsim::InputEvent;
using rfbsim::detail::HeldKeys;

namespace {
InputEvent key(int client, std::uint32_t keysym, bool down) {
  InputEvent e;
  e.kind = InputEvent::Kind::Key;
  e.client_id = client;
  e.keysym = keysym;
  e.down = down;
  return e;
}
const auto now = std::chrono::steady_clock::now();
}  // namespace

TEST_CASE("released keys are not released again") {
  HeldKeys held;
  held.record(key(1, 'w', true));
  held.record(key(1, 'w', false));
  CHECK(held.empty());
  CHECK(held.release_client(1, now).empty());
}

TEST_CASE("a leaving client's held keys are released as synthetic key-ups") {
  HeldKeys held;
  held.record(key(1, 'w', true));
  held.record(key(1, 0xff52, true));
  held.record(key(1, 'w', true));  // auto-repeat counts once
  const auto releases = held.release_client(1, now);
  REQUIRE(releases.size() == 2);
  for (const auto& r : releases) {
    CHECK_FALSE(r.down);
    CHECK(r.client_id == 0);
  }
  CHECK(releases[0].keysym == 'w');
  CHECK(releases[1].keysym == 0xff52);
  CHECK(held.empty());
}

TEST_CASE("a key another client still holds stays down") {
  HeldKeys held;
  held.record(key(1, 'w', true));
  held.record(key(2, 'w', true));
  CHECK(held.release_client(1, now).empty());
  CHECK(held.is_held('w'));
  const auto all = held.release_all(now);
  REQUIRE(all.size() == 1);
  CHECK(all[0].keysym == 'w');
  CHECK_FALSE(held.is_held('w'));
}
