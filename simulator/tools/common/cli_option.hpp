// SPDX-License-Identifier: GPL-2.0-or-later
// The option syntax sim_report and sim_replay share: "--name VALUE" or "--name=VALUE".
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace rfbsim::tools {

/// Whether `arg` is option `name`, given as "--name" or "--name=...".
bool is_option(const std::string& arg, const std::string& name);

/// The value of option `name` at args[i], from "--name VALUE" (i then moves past VALUE) or "--name=VALUE".
/// None, with `error` set to "<name> needs <what>", when the value is missing or empty.
std::optional<std::string> option_value(const std::vector<std::string>& args, std::size_t& i, const std::string& name,
                                        const char* what, std::string& error);

}  // namespace rfbsim::tools
