// SPDX-License-Identifier: GPL-2.0-or-later
// sim_manager's command line: one CLI11 option per setting of the table (settings_table.hpp), plus the
// manager's own --config, --sign and --print-config. CLI11 splits the arguments and writes --help; the table's
// kinds check the values, the same way as the file's.
#include <algorithm>
#include <map>

#include "cli/command_line.hpp"
#include "config/config.hpp"
#include "config/settings_table.hpp"
#include "http/routes.hpp"

namespace rfbsim::manager {

namespace {

using config_table::find_setting;
using config_table::settings;

// The settings a flag repeats, one argument each, rather than taking a comma list: a program's argument or a copy
// command's path may hold a comma.
const std::map<std::string, std::string> kRepeatedFlags = {{"session_args", "--session-arg"},
                                                            {"after_session_command", "--after-session-command"}};

// The secrets the environment may give, and where each goes.
struct SecretSource {
  const char* key;
  const char* variable;
  std::string ManagerConfig::*field;
};
const SecretSource kSecretSources[] = {{"admin_token", "RFBSIM_ADMIN_TOKEN", &ManagerConfig::admin_token},
                                       {"link_secret", "RFBSIM_LINK_SECRET", &ManagerConfig::link_secret}};

// What the command line gave, before any of it is checked.
struct Given {
  std::vector<std::string> config_files;
  std::string sign_query;
  bool help = false;
  bool print_config = false;
  std::map<std::string, std::string> values;                  ///< by key, for a setting given once
  std::map<std::string, std::vector<std::string>> repeated;  ///< by key, for kRepeatedFlags
};

// One option for each setting, and the manager's own; `given` receives what the arguments say.
void declare(CLI::App& app, Given& given) {
  cli::configure(app);
  app.add_flag("-h,--help", given.help, "print this help and exit");
  // --config and the repeated flags take their next argument as it is, even one that starts with "--"
  // (--session-arg --time-limit): CLI11 hands a required value over without looking at it.
  app.add_option("--config", given.config_files, "the YAML file of settings; flags win over it")
      ->type_name("FILE")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_option("--sign", given.sign_query, "print QUERY with its link signature (needs a link secret) and exit")
      ->type_name("QUERY");
  app.add_flag("--print-config", given.print_config,
               "print the effective settings (defaults, file, flags and environment) as a config file and exit");
  const ManagerConfig defaults;
  for (const config_table::Setting& setting : settings()) {
    std::string help = config_table::plain_text(setting.help);
    const auto shown = setting.kind.show(defaults);
    std::string default_text;
    if (shown && !shown->empty()) {
      for (const std::string& value : *shown) default_text += (default_text.empty() ? "" : ",") + value;
    }
    if (const std::string note = config_table::plain_text(setting.default_note); !note.empty()) {
      default_text = default_text.empty() ? note : default_text + "; " + note;
    }
    const std::string type = setting.kind.value_name + (setting.kind.range.empty() ? "" : ":" + setting.kind.range);
    CLI::Option* option = nullptr;
    if (const auto repeated = kRepeatedFlags.find(setting.key); repeated != kRepeatedFlags.end()) {
      option = app.add_option(repeated->second, given.repeated[setting.key], help + " (repeat as needed)")
                   ->expected(1)
                   ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    } else {
      if (setting.kind.list) help += " (comma-separated)";
      option = app.add_option(config_table::flag_of(setting.key), given.values[setting.key], help);
    }
    option->type_name(type)->default_str(default_text);
  }
}

}  // namespace

ConfigOutcome parse_manager_args(const std::vector<std::string>& args,
                                 const std::vector<std::pair<std::string, std::string>>& environment) {
  ConfigOutcome outcome;
  CLI::App app("sim_manager: one link per participant, one simulator per link", "sim_manager");
  Given given;
  declare(app, given);
  if (std::string problem = cli::parse(app, args); !problem.empty()) {
    outcome.help = given.help;
    if (!outcome.help) outcome.error = problem;
    return outcome;
  }
  if (given.help) {
    outcome.help = true;
    return outcome;
  }
  // The files first, in their order, so that flags always win over them.
  for (const std::string& file : given.config_files) {
    outcome = load_config_file(file, outcome.config);
    if (!outcome.error.empty()) return outcome;
  }
  outcome.sign_query = given.sign_query;
  outcome.print_config = given.print_config;
  for (const config_table::Setting& setting : settings()) {
    std::vector<std::string> values;
    std::string shown_value;
    if (kRepeatedFlags.count(setting.key) != 0) {
      if (app.get_option(kRepeatedFlags.at(setting.key))->count() == 0) continue;
      values = given.repeated.at(setting.key);  // the flags' list replaces the file's as a whole
      shown_value = values.back();
    } else {
      if (app.get_option(config_table::flag_of(setting.key))->count() == 0) continue;
      shown_value = given.values.at(setting.key);
      values = setting.kind.list ? config_table::split_commas(shown_value) : std::vector<std::string>{shown_value};
    }
    const std::string problem = setting.kind.apply(outcome.config, values);
    if (!problem.empty()) {
      // A repeated flag's list is checked as a whole, and the problem names its item. Secrets are never echoed:
      // error messages end up in logs and terminals.
      if (kRepeatedFlags.count(setting.key) != 0) {
        outcome.error = problem;
      } else {
        outcome.error = config_table::flag_of(setting.key) + (setting.secret ? "" : " '" + shown_value + "'") + ": " + problem;
      }
      return outcome;
    }
  }
  for (const SecretSource& secret : kSecretSources) {
    std::string& field = outcome.config.*secret.field;
    // The environment (e.g. a systemd EnvironmentFile) keeps a secret out of `ps`. It fills a secret the flags
    // and files left empty, or one a printed config left as a placeholder.
    const auto given_value = std::find_if(environment.begin(), environment.end(),
                                          [&](const auto& variable) { return variable.first == secret.variable; });
    if (given_value != environment.end() && (field.empty() || field == config_table::kSecretPlaceholder)) {
      const std::string problem = find_setting(secret.key)->kind.apply(outcome.config, {given_value->second});
      if (!problem.empty() || field == config_table::kSecretPlaceholder) {
        outcome.error = std::string(secret.variable) + ": " +
                        (problem.empty() ? "must be the secret itself, not " + field : problem);
        return outcome;
      }
    }
    // A printed config stands for its secrets with a placeholder: printing it again is fine, serving is not.
    if (field == config_table::kSecretPlaceholder && !given.print_config) {
      outcome.error = std::string(secret.key) + " is " + field + " (as --print-config writes it): give the secret " +
                      "itself by " + config_table::flag_of(secret.key) + ", the file or " + secret.variable;
      return outcome;
    }
  }
  // In a cluster each host owns "/<host_id>" of the balancer's URL space unless told otherwise (the balancer
  // routes /<id>/... to host <id>, and a registry answer sends a participant to /<id>/start).
  ManagerConfig& config = outcome.config;
  if (config.path_prefix.empty() && !config.cluster_peers.empty() && is_path_prefix("/" + config.host_id)) {
    config.path_prefix = "/" + config.host_id;
  }
  finish_config(config);
  if (outcome.error.empty()) outcome.error = validate_config(outcome.config);
  return outcome;
}

std::string manager_usage() {
  CLI::App app("sim_manager: one link per participant, one simulator per link", "sim_manager");
  Given given;
  declare(app, given);
  std::string help = app.help();
  while (!help.empty() && help.back() == '\n') help.pop_back();
  return help +
         "\n\nEvery setting is also a key of the YAML file given by --config (--max-sessions N is max_sessions: N;\n"
         "--ros-connect URL is connect: URL under ros:). docs/deployment.md explains each one.\n";
}

}  // namespace rfbsim::manager
