// SPDX-License-Identifier: GPL-2.0-or-later
// KeyControls: held keys integrate position-servo targets, or switch other actuators fully on.
#include "key_controls.hpp"

#include <algorithm>

namespace {

constexpr std::uint32_t kUp = 0xff52, kDown = 0xff54, kLeft = 0xff51, kRight = 0xff53;
constexpr double kTargetRate = 1.0;  // position-servo target speed, units per second

// Letters in lower case, so that Shift or Caps Lock does not change what a key does.
std::uint32_t lower(std::uint32_t keysym) { return keysym >= 'A' && keysym <= 'Z' ? keysym + 0x20 : keysym; }

// The actuator called `name`, else the one at `index`, else -1.
int actuator(const mjModel* model, const char* name, int index) {
  const int id = mj_name2id(model, mjOBJ_ACTUATOR, name);
  if (id >= 0) return id;
  return index < model->nu ? index : -1;
}

bool is_position_servo(const mjModel* model, int i) { return model->actuator_biastype[i] == mjBIAS_AFFINE; }

// The control range of actuator i, or [-1, 1] when it is not limited.
std::pair<mjtNum, mjtNum> control_range(const mjModel* model, int i) {
  if (model->actuator_ctrllimited[i] == 0) return {-1, 1};
  return {model->actuator_ctrlrange[2 * i], model->actuator_ctrlrange[2 * i + 1]};
}

}  // namespace

KeyControls::KeyControls(const mjModel* model) : target_(static_cast<std::size_t>(model->nu), 0) {
  bindings_ = {{actuator(model, "shoulder", 0), {'w', kUp}, {'s', kDown}},
               {actuator(model, "yaw", 1), {'a', kLeft}, {'d', kRight}},
               {actuator(model, "elbow", 2), {'e'}, {'q'}}};
  std::erase_if(bindings_, [](const Binding& b) { return b.actuator < 0; });
  reset_targets(model);
}

void KeyControls::reset_targets(const mjModel* model) {
  for (int i = 0; i < model->nu; ++i) {
    const auto [low, high] = control_range(model, i);
    target_[static_cast<std::size_t>(i)] = std::clamp<mjtNum>(0, low, high);
  }
}

void KeyControls::key(std::uint32_t keysym, bool down, const mjModel* model, mjData* data) {
  const std::uint32_t key = lower(keysym);
  if (!down) {
    held_.erase(key);
    return;
  }
  held_.insert(key);
  if (key == 'r') {
    mj_resetData(model, data);
    reset_targets(model);
  }
}

int KeyControls::direction(const Binding& binding) const {
  const auto any_held = [&](const std::vector<std::uint32_t>& keys) {
    return std::any_of(keys.begin(), keys.end(), [&](std::uint32_t k) { return held_.contains(k); });
  };
  return (any_held(binding.plus) ? 1 : 0) - (any_held(binding.minus) ? 1 : 0);
}

void KeyControls::apply(double dt, const mjModel* model, mjData* data) {
  for (int i = 0; i < model->nu; ++i) {
    if (is_position_servo(model, i)) data->ctrl[i] = target_[static_cast<std::size_t>(i)];
  }
  for (const Binding& binding : bindings_) {
    const int i = binding.actuator;
    const int dir = direction(binding);
    const auto [low, high] = control_range(model, i);
    if (is_position_servo(model, i)) {
      mjtNum& target = target_[static_cast<std::size_t>(i)];
      target = std::clamp<mjtNum>(target + dir * kTargetRate * dt, low, high);
      data->ctrl[i] = target;
    } else {
      data->ctrl[i] = dir > 0 ? high : dir < 0 ? low : 0;
    }
  }
}
