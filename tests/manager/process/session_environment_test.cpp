// SPDX-License-Identifier: GPL-2.0-or-later
// What a real sim_rfb session inherits from a real sim_manager: the manager holds its admin token and link
// secret in its environment (as a systemd EnvironmentFile gives them), and the session, read from the outside
// through /proc, has neither, nor any other variable off the allow-list; it has no core limit above 0, umask
// 077, and the files it writes in its folder are the owner's alone.
#include <catch2/catch.hpp>

#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "scoped_env.hpp"
#include "manager_process.hpp"
#include "sim_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::kAdminToken;
using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;
using rfbsim::test::with_small_sessions;

namespace {

constexpr const char* kLinkSecret = "env-link-secret-0123456789";

using rfbsim::test::ScopedEnv;

// The whole content of a /proc file.
std::string read_proc(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The NAME=value entries of process `pid`'s environment, as exec gave it.
std::vector<std::string> environment_of(pid_t pid) {
  const std::string text = read_proc("/proc/" + std::to_string(pid) + "/environ");
  std::vector<std::string> entries;
  std::istringstream stream(text);
  for (std::string entry; std::getline(stream, entry, '\0');) entries.push_back(entry);
  return entries;
}

// The value of `name` in `entries`, if set.
std::optional<std::string> value_of(const std::vector<std::string>& entries, const std::string& name) {
  for (const std::string& entry : entries) {
    if (entry.rfind(name + "=", 0) == 0) return entry.substr(name.size() + 1);
  }
  return std::nullopt;
}

// The line of /proc/PID/<file> that starts with `prefix` ("" when there is none).
std::string proc_line(pid_t pid, const std::string& file, const std::string& prefix) {
  std::istringstream text(read_proc("/proc/" + std::to_string(pid) + "/" + file));
  for (std::string line; std::getline(text, line);) {
    if (line.rfind(prefix, 0) == 0) return line;
  }
  return "";
}

}  // namespace

TEST_CASE("a session inherits none of the manager's secrets, only its allow-listed environment",
          "[manager][secrets]") {
  TempDir data;
  std::optional<ManagerUnderTest> manager;
  {
    const ScopedEnv admin("RFBSIM_ADMIN_TOKEN", kAdminToken);
    const ScopedEnv secret("RFBSIM_LINK_SECRET", kLinkSecret);
    const ScopedEnv foo("FOO", "bar");
    const ScopedEnv key("RFBSIM_ADDRESS_KEY", "study-key-for-the-test");
    manager.emplace(data.path(), with_small_sessions({}));
  }
  // The test means something only if the manager itself holds the secrets.
  const auto manager_env = environment_of(manager->pid());
  REQUIRE(value_of(manager_env, "RFBSIM_ADMIN_TOKEN") == std::string(kAdminToken));
  REQUIRE(value_of(manager_env, "FOO") == std::string("bar"));

  // With the link secret set, /start needs a signed link: sim_manager --sign makes one.
  const auto signed_link = rfbsim::test::run_to_exit(rfbsim::test::sim_manager_path(),
                                                     {"--link-secret", kLinkSecret, "--sign", "uid=env-1&scenario=warehouse"});
  REQUIRE(signed_link.output.size() > 1);
  const std::string token = token_from_redirect(manager->start(signed_link.output.substr(0, signed_link.output.size() - 1)));
  REQUIRE(token.size() == 32);
  REQUIRE(manager->wait_for_state(token, "running"));
  const auto row = manager->row_for_token(token);
  REQUIRE(row);
  const pid_t session = static_cast<pid_t>(row->pid);
  REQUIRE(session > 0);

  const auto env = environment_of(session);
  std::string joined;
  for (const std::string& entry : env) joined += entry + "\n";
  INFO(joined);
  REQUIRE_FALSE(env.empty());
  CHECK(joined.find(kAdminToken) == std::string::npos);
  CHECK(joined.find(kLinkSecret) == std::string::npos);
  CHECK_FALSE(value_of(env, "RFBSIM_ADMIN_TOKEN"));
  CHECK_FALSE(value_of(env, "RFBSIM_LINK_SECRET"));
  CHECK_FALSE(value_of(env, "FOO"));
  CHECK(value_of(env, "RFBSIM_ADDRESS_KEY") == std::string("study-key-for-the-test"));
  CHECK(value_of(env, "PATH"));
  CHECK(value_of(env, "HOME") == row->data_path);
  // Only names of the allow-list, the RFBSIM_ prefix and HOME.
  for (const std::string& entry : env) {
    const std::string name = entry.substr(0, entry.find('='));
    const bool allowed = name == "HOME" || name.rfind("RFBSIM_", 0) == 0 || name == "PATH" || name == "LANG" ||
                         name == "LC_ALL" || name == "TZ" || name == "EGL_PLATFORM" ||
                         name == "LIBGL_ALWAYS_SOFTWARE" || name == "GALLIUM_DRIVER" ||
                         name == "MESA_LOADER_DRIVER_OVERRIDE" || name == "LP_NUM_THREADS" ||
                         name == "__EGL_VENDOR_LIBRARY_FILENAMES" || name == "__EGL_VENDOR_LIBRARY_DIRS";
    CHECK(allowed);
  }

  // No core files, and a umask that keeps what it writes private.
  CHECK(proc_line(session, "limits", "Max core file size").find(" 0                    0 ") != std::string::npos);
  CHECK(proc_line(session, "status", "Umask:") == "Umask:\t0077");

  // What it wrote in its folder so far (its log, its recording) is the owner's alone.
  const std::filesystem::path folder = row->data_path;
  REQUIRE(rfbsim::test::eventually([&] { return std::filesystem::exists(folder / "session.json"); }, 20s));
  int files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    struct stat info {};
    REQUIRE(::stat(entry.path().c_str(), &info) == 0);
    INFO(entry.path());
    CHECK((info.st_mode & 077) == 0);
    ++files;
  }
  CHECK(files >= 2);  // session.log and session.json at least
}
