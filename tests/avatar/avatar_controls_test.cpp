// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "avatar/avatar_controls.hpp"

using rfbsim::sim::AvatarControls;
using rfbsim::sim::fold_letter_case;

TEST_CASE("W A S D map to walking and turning - in both cases") {
  AvatarControls controls;
  CHECK(controls.apply_key('w', true));
  CHECK(controls.state().forward);
  CHECK(controls.apply_key('A', true));
  CHECK(controls.state().turn_left);
  CHECK(controls.apply_key('S', true));
  CHECK(controls.state().backward);
  CHECK(controls.apply_key('d', true));
  CHECK(controls.state().turn_right);
}

TEST_CASE("a release in the other letter case releases the key") {
  AvatarControls controls;
  controls.apply_key('w', true);
  controls.apply_key('W', false);  // Shift went down while W was held
  CHECK_FALSE(controls.state().forward);
}

TEST_CASE("Up and Down move the camera  other keys do nothing") {
  AvatarControls controls;
  CHECK(controls.apply_key(0xff52, true));
  CHECK(controls.state().camera_up);
  CHECK(controls.apply_key(0xff54, true));
  CHECK(controls.state().camera_down);
  const auto before = controls.state();
  CHECK_FALSE(controls.apply_key('q', true));
  CHECK_FALSE(controls.apply_key(0xffe1, true));  // Shift
  CHECK(controls.state() == before);
  controls.release_all();
  CHECK(controls.state() == rfbsim::sim::ControlState{});
}

TEST_CASE("letter case folding touches only A-Z") {
  CHECK(fold_letter_case('W') == 'w');
  CHECK(fold_letter_case('w') == 'w');
  CHECK(fold_letter_case(0xff52) == 0xff52);
  CHECK(fold_letter_case('[') == '[');
}
