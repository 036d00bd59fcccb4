// SPDX-License-Identifier: GPL-2.0-or-later
// Session command lines.
#include "launch_plan.hpp"

#include <algorithm>

#include "session_process.hpp"
#include "web_policy.hpp"

namespace rfbsim::manager {

namespace {

void replace_all(std::string& text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

}  // namespace

std::vector<std::string> session_arguments(const ManagerConfig& config, const StartRequest& request,
                                           const LaunchContext& context) {
  const std::string scenario = scenario_argument(config.scenarios, request.scenario);
  if (config.session_kind == SessionKind::kRfb) {
    std::vector<std::string> args = config.session_args;
    for (std::string& arg : args) {
      replace_all(arg, "{port}", std::to_string(context.port));
      replace_all(arg, "{scenario}", scenario);
      replace_all(arg, "{seed}", std::to_string(context.seed));
      replace_all(arg, "{uid}", request.uid);
      replace_all(arg, "{data_dir}", context.data_dir);
    }
    return args;
  }
  std::vector<std::string> args = {"--port",   "0",
                                   "--bind",   "127.0.0.1",
                                   "--rfb-only", "--ready-fd",
                                   std::to_string(kReadyFd), "--scenario",
                                   scenario,   "--seed",
                                   std::to_string(context.seed)};
  for (const auto& [name, value] : request.overrides) {
    const auto param = std::find_if(kOverrideParams.begin(), kOverrideParams.end(),
                                    [&name = name](const OverrideParam& p) { return name == p.name; });
    args.emplace_back(param->flag);
    args.push_back(value);
  }
  args.insert(args.end(), config.session_args.begin(), config.session_args.end());
  return args;
}

std::string parameters_json(const StartRequest& request, std::uint64_t seed) {
  std::string json = "{\"uid\":\"" + json_escape(request.uid) + "\",\"scenario\":\"" + json_escape(request.scenario) +
                     "\",\"seed\":\"" + std::to_string(seed) + "\"";
  for (const auto& [name, value] : request.overrides) {
    json += ",\"" + json_escape(name) + "\":\"" + json_escape(value) + "\"";
  }
  return json + "}";
}

}  // namespace rfbsim::manager
