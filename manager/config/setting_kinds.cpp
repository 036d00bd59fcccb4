// SPDX-License-Identifier: GPL-2.0-or-later
#include "config/setting_kinds.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <filesystem>

#include "cluster/uid_registry.hpp"

namespace rfbsim::manager::config_table {

namespace {

using Values = std::vector<std::string>;
using Shown = std::optional<Values>;

// The longest timeout a setting takes: a week (a guard against typos, not a study's limit).
constexpr long long kMaxSettingSeconds = 7LL * 24 * 3600;

// The abuse limits' bounds: a count far past any study, and an hour.
constexpr int kMaxAbuseCount = 1000000;
constexpr long long kMaxAbuseSeconds = 3600;

std::optional<std::vector<std::string>> one(std::string value) {
  return std::vector<std::string>{std::move(value)};
}

std::optional<std::vector<std::string>> unless_empty(const std::string& value) {
  if (value.empty()) return std::nullopt;
  return one(value);
}

// A host name as DNS compares it: ASCII letters without case.
std::string lower_case(std::string text) {
  for (char& ch : text) {
    if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
  }
  return text;
}

// "ID=ADDRESS:PORT", one entry of cluster_peers.
std::optional<ClusterPeer> parse_cluster_peer(const std::string& entry) {
  const std::size_t eq = entry.find('=');
  const std::size_t colon = entry.rfind(':');
  if (eq == std::string::npos || colon == std::string::npos || colon < eq) return std::nullopt;
  ClusterPeer peer;
  peer.id = entry.substr(0, eq);
  peer.address = entry.substr(eq + 1, colon - eq - 1);
  if (!is_host_id(peer.id) || !parse_integer(entry.substr(colon + 1), 1, 65535, peer.port)) return std::nullopt;
  // A host name or a numeric IPv4 address: letters, digits, dots and dashes.
  if (peer.address.empty() || peer.address.size() > 253) return std::nullopt;
  for (const char ch : peer.address) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '.' ||
                    ch == '-';
    if (!ok) return std::nullopt;
  }
  return peer;
}

}  // namespace

ValueKind integer(int ManagerConfig::*field, int low, int high) {
  const std::string range = std::to_string(low) + ".." + std::to_string(high);
  return {"N", range, false,
          [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
            if (!parse_integer(v.front(), low, high, c.*field)) return "expected an integer " + range;
            return "";
          },
          [=](const ManagerConfig& c) { return one(std::to_string(c.*field)); }};
}

ValueKind seconds(std::chrono::seconds ManagerConfig::*field, long long low) {
  const std::string range = std::to_string(low) + ".." + std::to_string(kMaxSettingSeconds);
  return {"S", range, false,
          [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
            long long value = 0;
            if (!parse_integer(v.front(), low, kMaxSettingSeconds, value)) return "expected whole seconds " + range;
            c.*field = std::chrono::seconds(value);
            return "";
          },
          [=](const ManagerConfig& c) { return one(std::to_string((c.*field).count())); }};
}

ValueKind abuse_count(int AbuseLimits::*field) {
  const std::string range = "0.." + std::to_string(kMaxAbuseCount) + ", 0 = off";
  return {"N", range, false,
          [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
            if (!parse_integer(v.front(), 0, kMaxAbuseCount, c.abuse.*field)) return "expected " + range;
            return "";
          },
          [=](const ManagerConfig& c) { return one(std::to_string(c.abuse.*field)); }};
}

ValueKind abuse_seconds(std::chrono::seconds AbuseLimits::*field) {
  const std::string range = "0.." + std::to_string(kMaxAbuseSeconds) + ", 0 = off";
  return {"S", range, false,
          [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
            long long value = 0;
            if (!parse_integer(v.front(), 0LL, kMaxAbuseSeconds, value)) return "expected whole seconds " + range;
            c.abuse.*field = std::chrono::seconds(value);
            return "";
          },
          [=](const ManagerConfig& c) { return one(std::to_string((c.abuse.*field).count())); }};
}

ValueKind text(std::string ManagerConfig::*field, std::string value_name, std::size_t min_length) {
  const std::string range = min_length <= 1 ? "" : std::to_string(min_length) + " characters or more";
  return {std::move(value_name), range, false,
          [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
            if (v.front().size() < min_length) return min_length <= 1 ? "must not be empty" : "must be at least " + range;
            c.*field = v.front();
            return "";
          },
          [=](const ManagerConfig& c) { return unless_empty(c.*field); }};
}

ValueKind boolean(bool ManagerConfig::*field) {
  return {"B", "true or false", false,
          [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
            if (v.front() == "true" || v.front() == "yes" || v.front() == "1") {
              c.*field = true;
            } else if (v.front() == "false" || v.front() == "no" || v.front() == "0") {
              c.*field = false;
            } else {
              return "expected true or false";
            }
            return "";
          },
          [=](const ManagerConfig& c) { return one(c.*field ? "true" : "false"); }};
}

ValueKind ipv4_address(std::string ManagerConfig::*field) {
  return checked_text(field, "ADDR", "", [](const std::string& value) -> std::string {
    in_addr address{};
    if (::inet_pton(AF_INET, value.c_str(), &address) != 1) return "expected a numeric IPv4 address";
    return "";
  });
}

ValueKind choice(std::string ManagerConfig::*field, std::vector<std::string> names) {
  return checked_text(field, bar_list(names), "", [names](const std::string& value) -> std::string {
    for (const std::string& name : names) {
      if (value == name) return "";
    }
    return "expected " + spoken_list(names);
  });
}

ValueKind checked_text(std::string ManagerConfig::*field, std::string value_name, std::string range,
                       std::function<std::string(const std::string&)> problem) {
  return {std::move(value_name), std::move(range), false,
          [=](ManagerConfig& c, const std::vector<std::string>& v) -> std::string {
            if (std::string found = problem(v.front()); !found.empty()) return found;
            c.*field = v.front();
            return "";
          },
          [=](const ManagerConfig& c) { return unless_empty(c.*field); }};
}
// A secret of 16 characters or more, which messages never echo. kSecretPlaceholder (what --print-config writes for
// it) stands for a secret that the command line or the environment gives: parse_manager_args insists on that.
ValueKind secret(std::string ManagerConfig::*field) {
  return {"T", "16 characters or more", false,
          [=](ManagerConfig& c, const Values& v) -> std::string {
            if (v.front().size() < 16 && v.front() != kSecretPlaceholder) return "must be at least 16 characters";
            c.*field = v.front();
            return "";
          },
          [=](const ManagerConfig& c) -> Shown {
            if ((c.*field).empty()) return std::nullopt;
            return Values{kSecretPlaceholder};
          }};
}

// A list of entries each checked by `problem` ("" = fine).
ValueKind checked_list(Values ManagerConfig::*field, std::string value_name,
                       std::function<std::string(const std::string&)> problem) {
  return {std::move(value_name), "", true,
          [=](ManagerConfig& c, const Values& v) -> std::string {
            for (const std::string& entry : v) {
              if (std::string found = problem(entry); !found.empty()) return found;
            }
            c.*field = v;
            return "";
          },
          [=](const ManagerConfig& c) -> Shown { return c.*field; }};
}

ValueKind cluster_peers() {
  return {"PEERS", "", true,
          [](ManagerConfig& c, const Values& v) -> std::string {
            std::vector<ClusterPeer> peers;
            for (const std::string& entry : v) {
              const auto peer = parse_cluster_peer(entry);
              if (!peer) return "'" + entry + "' is not ID=ADDRESS:PORT (ID: 1-32 of a-z 0-9 -, PORT: 1..65535)";
              for (const ClusterPeer& other : peers) {
                if (other.id == peer->id) return "host id '" + peer->id + "' is listed twice";
                // Two ids at one registry would be one acceptor voting twice: majorities would no longer intersect.
                if (other.port == peer->port && lower_case(other.address) == lower_case(peer->address)) {
                  return "hosts '" + other.id + "' and '" + peer->id + "' have the same registry " + peer->address +
                         ":" + std::to_string(peer->port);
                }
              }
              peers.push_back(*peer);
            }
            c.cluster_peers = std::move(peers);
            return "";
          },
          [](const ManagerConfig& c) -> Shown {
            Values entries;
            for (const ClusterPeer& peer : c.cluster_peers) {
              entries.push_back(peer.id + "=" + peer.address + ":" + std::to_string(peer.port));
            }
            return entries;
          }};
}

// A field of the ros section kept as given once `problem` ("" = fine) accepts it.
ValueKind ros_text(std::string RosSettings::*field, std::string value_name,
                   std::function<std::string(const std::string&)> problem) {
  return {std::move(value_name), "", false,
          [=](ManagerConfig& c, const Values& v) -> std::string {
            if (std::string found = problem(v.front()); !found.empty()) return found;
            c.ros.*field = v.front();
            return "";
          },
          [=](const ManagerConfig& c) -> Shown {
            if ((c.ros.*field).empty()) return std::nullopt;
            return Values{c.ros.*field};
          }};
}

// A file of the ros section, made absolute (a session runs in its own folder) and checked by `problem`.
ValueKind ros_file(std::string RosSettings::*field, std::string (*problem)(const std::string& path)) {
  ValueKind kind = ros_text(field, "FILE", [](const std::string&) { return std::string(); });
  kind.apply = [=](ManagerConfig& c, const Values& v) -> std::string {
    if (v.front().empty()) return "must not be empty";
    std::error_code ec;
    const std::string path = std::filesystem::absolute(v.front(), ec).string();
    if (ec) return "cannot make " + v.front() + " absolute: " + ec.message();
    if (std::string found = problem(path); !found.empty()) return found;
    c.ros.*field = path;
    return "";
  };
  return kind;
}

ValueKind ros_choice(std::string RosSettings::*field, const Values& names) {
  return ros_text(field, bar_list(names), [names](const std::string& value) -> std::string {
    if (std::find(names.begin(), names.end(), value) != names.end()) return "";
    return "expected " + spoken_list(names);
  });
}

// A count of the process limits, 0 = no limit.
ValueKind limit_count(std::uint64_t ProcessLimits::*field, std::uint64_t high, std::string value_name,
                      const std::string& what) {
  return {std::move(value_name), "0.." + std::to_string(high) + ", 0 = no limit", false,
          [=](ManagerConfig& c, const Values& v) -> std::string {
            if (!parse_integer<std::uint64_t>(v.front(), 0, high, c.limits.*field)) return "expected " + what + ", 0 = no limit";
            return "";
          },
          [=](const ManagerConfig& c) -> Shown { return Values{std::to_string(c.limits.*field)}; }};
}

}  // namespace rfbsim::manager::config_table
