// SPDX-License-Identifier: GPL-2.0-or-later
// CameraMode: whose eyes the participant's picture is taken from, and its names in files and links.
#pragma once

#include <optional>
#include <string_view>

namespace rfbsim::sim {

/// Which view the participant gets; a constant of the session (scenario `camera`, `--camera`, the link's).
enum class CameraMode {
  kThirdPerson,  ///< behind and above the avatar, which is drawn (the default)
  kFirstPerson,  ///< from the avatar's eyes, looking where it faces; its own body is not drawn
};

/// "third_person" or "first_person": the name scenario files, command lines, links and session.json use.
constexpr std::string_view camera_mode_name(CameraMode mode) {
  return mode == CameraMode::kFirstPerson ? "first_person" : "third_person";
}

/// The mode a name stands for; none for anything else (case matters, as for every other key).
constexpr std::optional<CameraMode> camera_mode_from_name(std::string_view name) {
  if (name == "third_person") return CameraMode::kThirdPerson;
  if (name == "first_person") return CameraMode::kFirstPerson;
  return std::nullopt;
}

}  // namespace rfbsim::sim
