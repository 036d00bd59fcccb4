// SPDX-License-Identifier: GPL-2.0-or-later
// KeyControls: the viewer's held keys drive a MuJoCo model's actuators.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>
#include <set>
#include <vector>

/// Key pairs move actuators while held: W/S or Up/Down the actuator named "shoulder" (else the first),
/// A/D or Left/Right "yaw" (else the second), E/Q "elbow" (else the third); R resets the model.
/// A position servo's target moves at up to 1 unit (rad or m) per second within its control range and stays
/// where the key left it; any other actuator gets its full control while the key is held and 0 after.
class KeyControls {
 public:
  /// Binds the keys to `model`'s actuators (a model with fewer actuators leaves keys unbound).
  explicit KeyControls(const mjModel* model);
  /// A key press or release (X11 keysym); R's press resets `data` at once.
  void key(std::uint32_t keysym, bool down, const mjModel* model, mjData* data);
  /// Writes the controls for the keys held now, `dt` seconds after the last call, into data->ctrl.
  void apply(double dt, const mjModel* model, mjData* data);

 private:
  struct Binding {
    int actuator = -1;
    std::vector<std::uint32_t> plus;   ///< keysyms (lower case) that raise the control
    std::vector<std::uint32_t> minus;  ///< keysyms that lower it
  };
  [[nodiscard]] int direction(const Binding& binding) const;
  void reset_targets(const mjModel* model);
  std::vector<Binding> bindings_;
  std::set<std::uint32_t> held_;
  std::vector<mjtNum> target_;  ///< per actuator: the position servos' targets
};
