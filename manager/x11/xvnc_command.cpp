// SPDX-License-Identifier: GPL-2.0-or-later
// Each Xvnc flag below exists in TigerVNC 1.12's `Xvnc -help`; VNC parameters take "-Name value" or "-Name=value".
#include "xvnc_command.hpp"

namespace rfbsim::x11 {

std::vector<std::string> xvnc_arguments(const SessionOptions& options, int display_fd) {
  const std::string& program = options.program.empty() ? std::string("x11") : options.program.front();
  const std::size_t slash = program.rfind('/');
  const std::string desktop = slash == std::string::npos ? program : program.substr(slash + 1);
  return {options.xvnc,
          "-displayfd", std::to_string(display_fd),
          "-auth", options.xauthority,
          "-nolisten", "tcp",
          "-rfbunixpath", options.rfb_socket,
          "-rfbunixmode", "0600",
          "-rfbport", "-1",
          "-SecurityTypes", "None",
          "-AlwaysShared",
          "-AcceptSetDesktopSize=0",
          "-geometry", std::to_string(options.width) + "x" + std::to_string(options.height),
          "-depth", std::to_string(options.depth),
          "-desktop", desktop.empty() ? std::string("x11") : desktop};
}

std::vector<std::string> program_environment(const std::vector<std::string>& inherited, int display,
                                             const std::string& xauthority) {
  std::vector<std::string> out;
  for (const std::string& entry : inherited) {
    if (entry.rfind("DISPLAY=", 0) == 0 || entry.rfind("XAUTHORITY=", 0) == 0) continue;
    out.push_back(entry);
  }
  out.push_back("DISPLAY=:" + std::to_string(display));
  out.push_back("XAUTHORITY=" + xauthority);
  return out;
}

}  // namespace rfbsim::x11
