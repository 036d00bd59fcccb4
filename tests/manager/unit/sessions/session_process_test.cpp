// SPDX-License-Identifier: GPL-2.0-or-later
// Real child processes. The product never runs a shell; these tests exec /bin/sh -c with their own fixed
// scripts as the *program*, to look at the child from the inside (its descriptors, limits, folder, signals).
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "reap_child.hpp"
#include "scoped_env.hpp"
#include "scratch_dir.hpp"
#include "sessions/session_process.hpp"

using rfbsim::manager::kReadyFd;
using rfbsim::manager::process_group_alive;
using rfbsim::manager::process_start_ticks;
using rfbsim::manager::signal_process_group;
using rfbsim::manager::spawn_session_process;
using rfbsim::manager::SpawnedProcess;
using rfbsim::manager::SpawnSpec;
using rfbsim::test::reap_child;
using rfbsim::test::ScratchDir;

namespace {

// A spec that runs `script` with /bin/sh in `dir`, logging to dir/session.log.
SpawnSpec shell(const ScratchDir& dir, const std::string& script) {
  SpawnSpec spec;
  spec.program = "/bin/sh";
  spec.args = {"-c", script};
  spec.working_dir = dir.path().string();
  spec.log_file = dir.path("session.log");
  return spec;
}

// Runs the spec to its end; returns the wait status and closes the ready pipe.
int run_to_end(const SpawnSpec& spec) {
  const SpawnedProcess process = spawn_session_process(spec);
  const int status = reap_child(process.pid);
  if (process.ready_fd >= 0) ::close(process.ready_fd);
  return status;
}

// Reads from the (non-blocking) ready pipe up to and including the first newline, or to end of file;
// gives up after 5 s.
std::string read_line(int fd) {
  std::string text;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (text.find('\n') == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    char buffer[64];
    const ssize_t got = ::read(fd, buffer, sizeof buffer);
    if (got == 0) break;
    if (got > 0) text.append(buffer, static_cast<std::size_t>(got));
  }
  return text;
}

// Whether this process has no child left, zombies included.
bool no_children_left() { return ::waitpid(-1, nullptr, WNOHANG) == -1 && errno == ECHILD; }

// Field 22 of /proc/PID/stat, read here independently of the code under test.
std::int64_t start_ticks_from_proc(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  std::getline(in, text);
  std::istringstream fields(text.substr(text.rfind(") ") + 2));  // field 3 onwards
  std::string field;
  for (int index = 3; index <= 22; ++index) fields >> field;
  return std::stoll(field);
}

// Makes this process the reaper of its orphaned grandchildren while it lives, so that the tests can reap
// every process they caused.
struct Subreaper {
  Subreaper() { ::prctl(PR_SET_CHILD_SUBREAPER, 1); }
  ~Subreaper() { ::prctl(PR_SET_CHILD_SUBREAPER, 0); }
  Subreaper(const Subreaper&) = delete;
  Subreaper& operator=(const Subreaper&) = delete;
};

}  // namespace

TEST_CASE("a session process leads its own group, logs its output and reports ready on fd 3") {
  ScratchDir dir;
  const SpawnedProcess process =
      spawn_session_process(shell(dir, "echo out; echo err >&2; printf 'ready 123\\n' >&3; exec sleep 100"));
  REQUIRE(process.pid > 0);
  CHECK(::getpgid(process.pid) == process.pid);
  CHECK(::getpgid(process.pid) != ::getpgid(0));
  REQUIRE(process.ready_fd >= 0);
  CHECK(read_line(process.ready_fd) == "ready 123\n");
  CHECK(process_group_alive(process.pid));

  REQUIRE(signal_process_group(process.pid, SIGKILL));
  const int status = reap_child(process.pid);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGKILL);
  CHECK(dir.read("session.log") == "out\nerr\n");
  ::close(process.ready_fd);
  CHECK(no_children_left());
}

TEST_CASE("the ready pipe's read end is non-blocking, close-on-exec and ends when the session does") {
  ScratchDir dir;
  const SpawnedProcess process = spawn_session_process(shell(dir, "exit 0"));
  REQUIRE(process.ready_fd >= 0);
  CHECK((::fcntl(process.ready_fd, F_GETFL) & O_NONBLOCK) != 0);
  CHECK((::fcntl(process.ready_fd, F_GETFD) & FD_CLOEXEC) != 0);
  const int status = reap_child(process.pid);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  // End of file, not "would block": the child held the only write end.
  char byte = 0;
  CHECK(::read(process.ready_fd, &byte, 1) == 0);
  ::close(process.ready_fd);
  CHECK(no_children_left());
}

TEST_CASE("the log is appended to, not truncated") {
  ScratchDir dir;
  dir.write("session.log", "earlier\n");
  CHECK(run_to_end(shell(dir, "echo later")) == W_EXITCODE(0, 0));
  CHECK(dir.read("session.log") == "earlier\nlater\n");
}

TEST_CASE("no descriptor of the parent leaks into the session") {
  ScratchDir dir;
  // Descriptors of ours without close-on-exec, as a careless library might leave them.
  const int leaked_low = ::open("/dev/null", O_RDONLY);
  const int leaked_high = ::fcntl(leaked_low, F_DUPFD, 40);
  REQUIRE(leaked_low >= 0);
  REQUIRE(leaked_high >= 40);

  SECTION("with the ready pipe: 0, 1, 2, 3 and the one ls reads the folder with") {
    CHECK(run_to_end(shell(dir, "ls /proc/self/fd")) == 0);
    CHECK(dir.read("session.log") == "0\n1\n2\n3\n4\n");
  }
  SECTION("without it: 0, 1, 2 and the one ls reads the folder with") {
    SpawnSpec spec = shell(dir, "ls /proc/self/fd");
    spec.ready_pipe = false;
    const SpawnedProcess process = spawn_session_process(spec);
    CHECK(process.ready_fd == -1);
    reap_child(process.pid);
    CHECK(dir.read("session.log") == "0\n1\n2\n3\n");
  }
  SECTION("stdin is /dev/null, stdout and stderr the log, fd 3 a pipe") {
    CHECK(run_to_end(shell(dir, "readlink /proc/$$/fd/0 /proc/$$/fd/1 /proc/$$/fd/2; "
                                "readlink /proc/$$/fd/3 | cut -c1-6")) == 0);
    const std::string log = dir.path("session.log");
    CHECK(dir.read("session.log") == "/dev/null\n" + log + "\n" + log + "\npipe:[\n");
  }
  ::close(leaked_low);
  ::close(leaked_high);
  CHECK(no_children_left());
}

TEST_CASE("the session gets the resource limits") {
  ScratchDir dir;
  SpawnSpec spec = shell(dir, "ulimit -n; ulimit -H -n; ulimit -v; ulimit -H -v; ulimit -t; ulimit -H -t");
  spec.limits.open_files = 64;
  spec.limits.address_space_bytes = 1ULL << 30;
  spec.limits.cpu_seconds = 100;
  CHECK(run_to_end(spec) == 0);
  // dash prints -v in KiB; the CPU limit's hard value is 5 s above the soft one.
  CHECK(dir.read("session.log") == "64\n64\n1048576\n1048576\n100\n105\n");
}

TEST_CASE("limits of 0 leave the inherited ones") {
  ScratchDir dir;
  rlimit files{};
  REQUIRE(::getrlimit(RLIMIT_NOFILE, &files) == 0);
  CHECK(run_to_end(shell(dir, "ulimit -n")) == 0);
  CHECK(dir.read("session.log") == std::to_string(files.rlim_cur) + "\n");
}

TEST_CASE("the session starts with no blocked signals and SIGPIPE at its default") {
  ScratchDir dir;
  // The manager blocks and ignores signals of its own; none of that may reach a session.
  sigset_t block, old_mask;
  sigemptyset(&block);
  sigaddset(&block, SIGTERM);
  sigaddset(&block, SIGCHLD);
  sigaddset(&block, SIGUSR1);
  REQUIRE(::pthread_sigmask(SIG_BLOCK, &block, &old_mask) == 0);
  const auto old_pipe = ::signal(SIGPIPE, SIG_IGN);
  // grep as the program itself (a shell blocks signals of its own around fork): it reads its own status.
  SpawnSpec spec = shell(dir, "");
  spec.program = "/bin/grep";
  spec.args = {"-E", "^Sig(Blk|Ign)", "/proc/self/status"};
  const int status = run_to_end(spec);
  ::signal(SIGPIPE, old_pipe);
  ::pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  CHECK(status == 0);

  const std::string log = dir.read("session.log");
  INFO(log);
  CHECK(log.rfind("SigBlk:\t0000000000000000\n", 0) == 0);
  const std::size_t ignored_at = log.find("SigIgn:\t");
  REQUIRE(ignored_at != std::string::npos);
  const unsigned long long ignored = std::stoull(log.substr(ignored_at + 8, 16), nullptr, 16);
  CHECK((ignored & (1ULL << (SIGPIPE - 1))) == 0);
}

TEST_CASE("the session runs in its working folder") {
  ScratchDir dir;
  std::filesystem::create_directory(dir.path() / "work");
  SpawnSpec spec = shell(dir, "pwd");
  spec.working_dir = dir.path("work");
  CHECK(run_to_end(spec) == 0);
  CHECK(dir.read("session.log") == dir.path("work") + "\n");
}

TEST_CASE("the program's arguments arrive as given, one by one") {
  ScratchDir dir;
  SpawnSpec spec = shell(dir, "printf '[%s]\\n' \"$0\" \"$@\"");
  spec.args.insert(spec.args.end(), {"name", "two words", "", "$HOME;rm -rf x", "'\""});
  CHECK(run_to_end(spec) == 0);
  CHECK(dir.read("session.log") == "[name]\n[two words]\n[]\n[$HOME;rm -rf x]\n['\"]\n");
}

TEST_CASE("a program that cannot run is an error naming it and the cause") {
  ScratchDir dir;
  SECTION("missing") {
    SpawnSpec spec = shell(dir, "");
    spec.program = dir.path("no-such-program");
    spec.args.clear();
    CHECK_THROWS_WITH(spawn_session_process(spec), "cannot run " + spec.program + ": No such file or directory");
  }
  SECTION("not executable") {
    SpawnSpec spec = shell(dir, "");
    spec.program = dir.write("not-executable", "#!/bin/sh\n");
    spec.args.clear();
    CHECK_THROWS_WITH(spawn_session_process(spec), "cannot run " + spec.program + ": Permission denied");
  }
  SECTION("a working folder that does not exist") {
    SpawnSpec spec = shell(dir, "true");
    spec.working_dir = dir.path("missing");
    CHECK_THROWS_WITH(spawn_session_process(spec),
                      "cannot enter the session folder " + spec.working_dir + ": No such file or directory");
  }
  SECTION("a log that cannot be opened") {
    SpawnSpec spec = shell(dir, "true");
    spec.log_file = dir.path("missing/session.log");
    CHECK_THROWS_WITH(spawn_session_process(spec),
                      "cannot open the session log " + spec.log_file + ": No such file or directory");
  }
  // The failed child was reaped by spawn_session_process itself.
  CHECK(no_children_left());
}

TEST_CASE("signalling the process group reaches the session's own children") {
  ScratchDir dir;
  Subreaper reaper;
  const SpawnedProcess process = spawn_session_process(shell(dir, "sleep 100 & echo $! >&3; exec sleep 100"));
  const std::string line = read_line(process.ready_fd);
  REQUIRE(!line.empty());
  const pid_t grandchild = static_cast<pid_t>(std::stol(line));
  CHECK(::getpgid(grandchild) == process.pid);

  REQUIRE(signal_process_group(process.pid, SIGTERM));
  const int status = reap_child(process.pid);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGTERM);
  // The grandchild, orphaned, came to us as the subreaper: it too died of SIGTERM.
  const int grandchild_status = reap_child(grandchild);
  CHECK(WIFSIGNALED(grandchild_status));
  CHECK(WTERMSIG(grandchild_status) == SIGTERM);

  CHECK_FALSE(process_group_alive(process.pid));
  CHECK_FALSE(signal_process_group(process.pid, SIGKILL));
  ::close(process.ready_fd);
  CHECK(no_children_left());
}

TEST_CASE("signal_process_group and process_group_alive never touch process groups 0 and 1") {
  CHECK_FALSE(signal_process_group(0, 0));
  CHECK_FALSE(signal_process_group(1, 0));
  CHECK_FALSE(signal_process_group(-1, 0));
  CHECK_FALSE(process_group_alive(0));
  CHECK_FALSE(process_group_alive(1));
  CHECK_FALSE(process_group_alive(-1));
}

TEST_CASE("process_start_ticks reads /proc and knows no dead process") {
  ScratchDir dir;
  SpawnSpec spec = shell(dir, "");
  spec.program = "/bin/sleep";
  spec.args = {"100"};
  const SpawnedProcess process = spawn_session_process(spec);
  const auto ticks = process_start_ticks(process.pid);
  REQUIRE(ticks);
  CHECK(*ticks == start_ticks_from_proc(process.pid));
  CHECK(*ticks > 0);
  CHECK(process.start_ticks == *ticks);
  CHECK(process_start_ticks(::getpid()) == start_ticks_from_proc(::getpid()));

  REQUIRE(signal_process_group(process.pid, SIGKILL));
  reap_child(process.pid);
  ::close(process.ready_fd);
  CHECK_FALSE(process_start_ticks(process.pid));
  CHECK_FALSE(process_group_alive(process.pid));
  CHECK_FALSE(process_start_ticks(-1));
  CHECK(no_children_left());
}

TEST_CASE("process_start_ticks copes with spaces and parentheses in the command name") {
  ScratchDir dir;
  const std::string odd = dir.path("a) b (c) 9");
  std::filesystem::copy_file("/bin/sleep", odd);
  std::filesystem::permissions(odd, std::filesystem::perms::owner_all);
  SpawnSpec spec = shell(dir, "");
  spec.program = odd;
  spec.args = {"100"};
  spec.ready_pipe = false;
  const SpawnedProcess process = spawn_session_process(spec);
  const auto ticks = process_start_ticks(process.pid);
  CHECK(ticks == start_ticks_from_proc(process.pid));
  CHECK(process.start_ticks == start_ticks_from_proc(process.pid));
  REQUIRE(signal_process_group(process.pid, SIGKILL));
  reap_child(process.pid);
  CHECK(no_children_left());
}

TEST_CASE("a session dies with the process that started it") {
  Subreaper reaper;
  ScratchDir dir;
  int report[2];
  REQUIRE(::pipe(report) == 0);
  // A stand-in manager: starts a session, tells us its pid, and dies at once.
  const pid_t manager = ::fork();
  REQUIRE(manager >= 0);
  if (manager == 0) {
    ::close(report[0]);
    pid_t session = -1;
    try {
      SpawnSpec spec = shell(dir, "");
      spec.program = "/bin/sleep";
      spec.args = {"100"};
      spec.ready_pipe = false;
      session = spawn_session_process(spec).pid;
    } catch (...) {
    }
    [[maybe_unused]] const auto written = ::write(report[1], &session, sizeof session);
    ::_exit(0);
  }
  ::close(report[1]);
  pid_t session = -1;
  REQUIRE(::read(report[0], &session, sizeof session) == static_cast<ssize_t>(sizeof session));
  ::close(report[0]);
  CHECK(WIFEXITED(reap_child(manager)));
  REQUIRE(session > 0);
  // Orphaned, the session came to us; the parent-death signal killed it.
  const int status = reap_child(session);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGKILL);
  CHECK(no_children_left());
}

namespace {

using rfbsim::manager::EnvVar;
using rfbsim::manager::session_environment;
using rfbsim::manager::session_variable_problem;
using Strings = std::vector<std::string>;

// A spec for the pure environment tests: only the fields session_environment reads matter.
SpawnSpec in_folder(const std::string& folder) {
  SpawnSpec spec;
  spec.working_dir = folder;
  return spec;
}

using rfbsim::test::ScopedEnv;

// A manager's environment with PATH, DISPLAY and LD_LIBRARY_PATH (neither allow-listed) and FOO.
std::vector<EnvVar> spec_env_manager_variables() {
  return {{"PATH", "/usr/bin"}, {"DISPLAY", ":0"}, {"LD_LIBRARY_PATH", "/opt/lib"}, {"FOO", "bar"}};
}

}  // namespace

TEST_CASE("a session's environment is the allow-listed part of the manager's, with HOME its folder") {
  const std::vector<EnvVar> manager = {{"PATH", "/opt/bin:/usr/bin"}, {"HOME", "/home/rfbsim"},
                                       {"FOO", "bar"},                {"LANG", "C.UTF-8"},
                                       {"RFBSIM_ADDRESS_KEY", "k1"},  {"RFBSIM_ADMIN_TOKEN", "admin-secret-1234"},
                                       {"RFBSIM_LINK_SECRET", "link-secret-1234"}, {"SSH_AUTH_SOCK", "/run/agent"},
                                       {"TZ", "Europe/Paris"},        {"LIBGL_ALWAYS_SOFTWARE", "1"},
                                       {"RFBSIM_SMTP_PASSWORD", "p"}, {"RFBSIM_HUD_FONT", "/f.ttf"},
                                       {"LD_PRELOAD", "/x.so"},       {"DISPLAY", ":0"}};
  CHECK(session_environment(manager, in_folder("/data/sessions/1-p1")) ==
        Strings{"PATH=/opt/bin:/usr/bin", "LANG=C.UTF-8", "RFBSIM_ADDRESS_KEY=k1", "TZ=Europe/Paris",
                "LIBGL_ALWAYS_SOFTWARE=1", "RFBSIM_HUD_FONT=/f.ttf", "HOME=/data/sessions/1-p1"});
}

TEST_CASE("a session without the manager's PATH gets a usual one") {
  CHECK(session_environment({{"FOO", "bar"}}, in_folder("/d")) == Strings{"PATH=/usr/local/bin:/usr/bin:/bin", "HOME=/d"});
  CHECK(session_environment({}, in_folder("")) == Strings{"PATH=/usr/local/bin:/usr/bin:/bin"});
}

TEST_CASE("the spec's variables are added and replace inherited ones") {
  SpawnSpec spec = in_folder("/d");
  spec.env = {{"DISPLAY", ":1"}, {"XAUTHORITY", "/d/.Xauthority"}, {"PATH", "/bin"}, {"HOME", "/srv/x11"}};
  CHECK(session_environment(spec_env_manager_variables(), spec) ==
        Strings{"DISPLAY=:1", "XAUTHORITY=/d/.Xauthority", "PATH=/bin", "HOME=/srv/x11"});
}

TEST_CASE("the spec's extra names are passed on from the manager's environment") {
  SpawnSpec spec = in_folder("/d");
  spec.pass_env = {"LD_LIBRARY_PATH", "ABSENT"};
  CHECK(session_environment(spec_env_manager_variables(), spec) ==
        Strings{"PATH=/usr/bin", "LD_LIBRARY_PATH=/opt/lib", "HOME=/d"});
}

TEST_CASE("the spec's extra names come before its variables") {
  SpawnSpec spec = in_folder("/d");
  spec.env = {{"DISPLAY", ":1"}, {"XAUTHORITY", "/d/.Xauthority"}, {"PATH", "/bin"}, {"HOME", "/srv/x11"}};
  spec.pass_env = {"LD_LIBRARY_PATH", "ABSENT"};
  CHECK(session_environment(spec_env_manager_variables(), spec) ==
        Strings{"LD_LIBRARY_PATH=/opt/lib", "DISPLAY=:1", "XAUTHORITY=/d/.Xauthority", "PATH=/bin", "HOME=/srv/x11"});
}

TEST_CASE("a name given twice in the manager's environment reaches the session once") {
  CHECK(session_environment({{"TZ", "UTC"}, {"TZ", "Europe/Paris"}}, in_folder("/d")) ==
        Strings{"TZ=UTC", "PATH=/usr/local/bin:/usr/bin:/bin", "HOME=/d"});
}

TEST_CASE("the manager's secrets are refused by name, whoever asks for them") {
  CHECK(session_variable_problem("RFBSIM_ADMIN_TOKEN") ==
        "RFBSIM_ADMIN_TOKEN is a secret of the manager's and never given to a session");
  CHECK_FALSE(session_variable_problem("RFBSIM_LINK_SECRET").empty());
  CHECK_FALSE(session_variable_problem("RFBSIM_FUTURE_API_TOKEN").empty());
  CHECK_FALSE(session_variable_problem("RFBSIM_DB_PASSWORD").empty());
  CHECK(session_variable_problem("RFBSIM_ADDRESS_KEY").empty());
  CHECK(session_variable_problem("DISPLAY").empty());
  CHECK(session_variable_problem("_x9").empty());
  CHECK(session_variable_problem("") == "'' is not an environment variable name");
  CHECK(session_variable_problem("9LIVES") == "'9LIVES' is not an environment variable name");
  CHECK(session_variable_problem("A=B") == "'A=B' is not an environment variable name");
  CHECK(session_variable_problem("A B") == "'A B' is not an environment variable name");

  // Asked for through the spec, a secret is an error, not a silent drop; the same for a bad name or value.
  SpawnSpec spec = in_folder("/d");
  spec.pass_env = {"RFBSIM_LINK_SECRET"};
  CHECK_THROWS_WITH(session_environment({{"RFBSIM_LINK_SECRET", "s"}}, spec),
                    "session environment: RFBSIM_LINK_SECRET is a secret of the manager's and never given to a "
                    "session");
  spec.pass_env.clear();
  spec.env = {{"RFBSIM_ADMIN_TOKEN", "x"}};
  CHECK_THROWS_AS(session_environment({}, spec), std::invalid_argument);
  spec.env = {{"A=B", "x"}};
  CHECK_THROWS_WITH(session_environment({}, spec), "session environment: 'A=B' is not an environment variable name");
  spec.env = {{"DISPLAY", std::string(":0\0:1", 5)}};
  CHECK_THROWS_WITH(session_environment({}, spec), "session environment: the value of DISPLAY holds a NUL byte");
}

TEST_CASE("a real session sees only its allow-listed environment, no core limit and umask 077") {
  ScratchDir dir;
  const ScopedEnv token("RFBSIM_ADMIN_TOKEN", "secret-admin-token-123");
  const ScopedEnv link("RFBSIM_LINK_SECRET", "secret-link-key-456");
  const ScopedEnv foo("FOO", "bar");
  const ScopedEnv key("RFBSIM_ADDRESS_KEY", "study-key");
  SpawnSpec spec = shell(dir, "");
  spec.program = "/usr/bin/env";  // the environment as exec gave it, with no shell adding its own variables
  spec.args = {};
  spec.env = {{"DISPLAY", ":7"}};
  CHECK(run_to_end(spec) == 0);
  const std::string log = dir.read("session.log");
  INFO(log);
  CHECK(log.find("secret") == std::string::npos);
  CHECK(log.find("FOO") == std::string::npos);
  CHECK(log.find("\nRFBSIM_ADDRESS_KEY=study-key\n") != std::string::npos);
  CHECK(log.find("\nDISPLAY=:7\n") != std::string::npos);
  CHECK(log.find("\nHOME=" + dir.path().string() + "\n") != std::string::npos);
  CHECK(("\n" + log).find("\nPATH=/") != std::string::npos);

  // The limits and the mask, from the inside: the soft and hard core limits, the umask, a file it creates.
  dir.write("session.log", "");
  SpawnSpec probe = shell(dir, "ulimit -c; ulimit -H -c; umask; echo x > made; mkdir made.d; "
                               "stat -c %a made made.d session.log");
  CHECK(run_to_end(probe) == 0);
  CHECK(dir.read("session.log") == "0\n0\n0077\n600\n700\n600\n");
}

TEST_CASE("the session log is created 0600, and an earlier one readable by others is narrowed") {
  ScratchDir dir;
  CHECK(run_to_end(shell(dir, "true")) == 0);
  CHECK((std::filesystem::status(dir.path("session.log")).permissions() & std::filesystem::perms::all) ==
        (std::filesystem::perms::owner_read | std::filesystem::perms::owner_write));
  ::chmod(dir.path("session.log").c_str(), 0644);
  CHECK(run_to_end(shell(dir, "echo again")) == 0);
  CHECK((std::filesystem::status(dir.path("session.log")).permissions() & std::filesystem::perms::all) ==
        (std::filesystem::perms::owner_read | std::filesystem::perms::owner_write));
  CHECK(dir.read("session.log") == "again\n");
}

TEST_CASE("a refused variable in the spec starts nothing and opens no log") {
  ScratchDir dir;
  SpawnSpec spec = shell(dir, "true");
  spec.env = {{"RFBSIM_LINK_SECRET", "x"}};
  CHECK_THROWS_AS(spawn_session_process(spec), std::invalid_argument);
  CHECK_FALSE(std::filesystem::exists(dir.path("session.log")));
  CHECK(no_children_left());
}
