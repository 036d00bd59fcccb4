// SPDX-License-Identifier: GPL-2.0-or-later
// Option values on the tools' command lines.
#include "cli_option.hpp"

namespace rfbsim::tools {

bool is_option(const std::string& arg, const std::string& name) {
  return arg == name || arg.rfind(name + "=", 0) == 0;
}

std::optional<std::string> option_value(const std::vector<std::string>& args, std::size_t& i, const std::string& name,
                                        const char* what, std::string& error) {
  const std::string& arg = args[i];
  std::string value;
  if (arg == name) {
    if (i + 1 >= args.size()) {
      error = name + " needs " + what;
      return std::nullopt;
    }
    value = args[++i];
  } else {
    value = arg.substr(name.size() + 1);
  }
  if (value.empty()) {
    error = name + " needs " + what;
    return std::nullopt;
  }
  return value;
}

}  // namespace rfbsim::tools
