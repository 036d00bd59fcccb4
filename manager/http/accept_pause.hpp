// SPDX-License-Identifier: GPL-2.0-or-later
// The pause of every listener of the manager (the public port, the registry, the agent check) after a failed
// accept: EMFILE, no descriptor left, would fail again at once, a busy loop on the I/O thread that every
// session's relay shares.
#pragma once

#include <chrono>

namespace rfbsim::manager {

/// How long a listener waits after a failed accept before it accepts again.
inline constexpr auto kAcceptPause = std::chrono::milliseconds(100);

}  // namespace rfbsim::manager
