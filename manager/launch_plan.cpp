// SPDX-License-Identifier: GPL-2.0-or-later
// Session command lines.
#include "launch_plan.hpp"

#include <algorithm>

#include "session_process.hpp"
#include "web_policy.hpp"

namespace rfbsim::manager {

namespace {

// Replaces every placeholder of `values` in one pass over `text`: a value put in is never searched again
// (a scenario file "/srv/{uid}.yaml" stays as it is).
std::string expand(const std::string& text, const std::vector<std::pair<std::string, std::string>>& values) {
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const auto match = std::find_if(values.begin(), values.end(),
                                    [&](const auto& value) { return text.compare(at, value.first.size(), value.first) == 0; });
    if (match == values.end()) {
      out.push_back(text[at++]);
    } else {
      out += match->second;
      at += match->first.size();
    }
  }
  return out;
}

}  // namespace

std::vector<std::string> session_arguments(const ManagerConfig& config, const StartRequest& request,
                                           const LaunchContext& context) {
  const std::string scenario = scenario_argument(config.scenarios, request.scenario);
  if (config.session_kind == SessionKind::kRfb) {
    const std::vector<std::pair<std::string, std::string>> values = {{"{port}", std::to_string(context.port)},
                                                                      {"{scenario}", scenario},
                                                                      {"{seed}", std::to_string(context.seed)},
                                                                      {"{uid}", request.uid},
                                                                      {"{t1}", request.code_success},
                                                                      {"{t2}", request.code_timeout},
                                                                      {"{data_dir}", context.data_dir}};
    std::vector<std::string> args;
    for (const std::string& arg : config.session_args) args.push_back(expand(arg, values));
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
  // Session data goes to the session's folder; the codes are shown in the picture when the task ends. The
  // relay names each browser's address in a PROXY line, which sim_rfb records hashed.
  args.insert(args.end(), {"--proxy-protocol", "--data-dir", context.data_dir, "--uid", request.uid});
  // The picture encoding, always named, so that the session's command line says what it ran with.
  args.insert(args.end(), {"--codec", config.codec});
  if (!request.code_success.empty()) args.insert(args.end(), {"--code-success", request.code_success});
  if (!request.code_timeout.empty()) args.insert(args.end(), {"--code-timeout", request.code_timeout});
  args.insert(args.end(), config.session_args.begin(), config.session_args.end());
  return args;
}

std::string parameters_json(const StartRequest& request, std::uint64_t seed) {
  std::string json = "{\"uid\":\"" + json_escape(request.uid) + "\",\"scenario\":\"" + json_escape(request.scenario) +
                     "\",\"seed\":\"" + std::to_string(seed) + "\"";
  for (const auto& [name, value] : request.overrides) {
    json += ",\"" + json_escape(name) + "\":\"" + json_escape(value) + "\"";
  }
  if (!request.code_success.empty()) json += ",\"t1\":\"" + json_escape(request.code_success) + "\"";
  if (!request.code_timeout.empty()) json += ",\"t2\":\"" + json_escape(request.code_timeout) + "\"";
  return json + "}";
}

}  // namespace rfbsim::manager
