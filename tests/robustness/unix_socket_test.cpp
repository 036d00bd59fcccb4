// SPDX-License-Identifier: GPL-2.0-or-later
// A server on a private unix socket (ServerOptions::unix_socket_path, sim_rfb --unix-socket) instead of
// TCP: mode 0600 so only its user (the manager) connects, RFB and PROXY lines as over TCP, a stale socket
// file replaced, any other file left alone, the file gone when the server stops.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rfb_test_client.hpp"
#include "rfb_wire.hpp"
#include "rfbsim/server.hpp"
#include "scratch_dir.hpp"
#include "served_scene.hpp"
#include "sim_process.hpp"

using rfbsim::test::eventually;
using rfbsim::test::kPatience;
using rfbsim::test::ScratchDir;
using namespace std::chrono_literals;

namespace {

rfbsim::ServerOptions unix_server(const std::string& path) {
  rfbsim::ServerOptions options;
  options.width = 64;
  options.height = 48;
  options.unix_socket_path = path;
  return options;
}

void submit_colour(rfbsim::Server& server, std::uint8_t value) {
  const auto& o = server.options();
  const auto bytes = static_cast<std::size_t>(o.width) * static_cast<std::size_t>(o.height) * 4U;
  const std::vector<std::uint8_t> pixels(bytes, value);
  server.submit(rfbsim::FrameView{pixels.data(), o.width, o.height, 0});
}

// The permission bits of the file at `path` and whether it is a socket; -1 when there is no file.
int socket_mode(const std::string& path, bool* is_socket = nullptr) {
  struct stat info {};
  if (::lstat(path.c_str(), &info) != 0) return -1;
  if (is_socket != nullptr) *is_socket = S_ISSOCK(info.st_mode);
  return static_cast<int>(info.st_mode & 07777);
}

// A connected unix stream socket, or -1.
int connect_unix(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  path.copy(address.sun_path, sizeof address.sun_path - 1);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// Reads exactly `n` bytes from `fd` within 5 s.
bool read_exact(int fd, std::size_t n, std::vector<std::uint8_t>& out) {
  out.assign(n, 0);
  std::size_t have = 0;
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (have < n) {
    pollfd p{fd, POLLIN, 0};
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) != 1) return false;
    const auto got = ::recv(fd, out.data() + have, n - have, 0);
    if (got <= 0) return false;
    have += static_cast<std::size_t>(got);
  }
  return true;
}

bool write_all(int fd, const std::vector<std::uint8_t>& bytes) {
  return ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(bytes.size());
}

// A stale socket file: bound, then closed without removing it (what a crash leaves).
void make_stale_socket(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  path.copy(address.sun_path, sizeof address.sun_path - 1);
  REQUIRE(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0);
  ::close(fd);
}

}  // namespace

TEST_CASE("a unix socket server: mode 0600, port 0, a libvncclient client gets frames, file removed at stop",
          "[robustness][unix]") {
  ScratchDir dir("rfbsim_unix");
  const std::string path = dir.path("sim.sock");
  std::vector<rfbsim::ClientInfo> seen;
  std::mutex seen_mutex;
  {
    rfbsim::ServerOptions options = unix_server(path);
    options.on_connect = [&](const rfbsim::ClientInfo& client) {
      std::lock_guard lock(seen_mutex);
      seen.push_back(client);
    };
    rfbsim::Server server(options);
    bool is_socket = false;
    CHECK(socket_mode(path, &is_socket) == 0600);
    CHECK(is_socket);
    CHECK(server.port() == 0);
    CHECK(server.url() == "unix:" + path);
    submit_colour(server, 90);
    rfbsim::test::RfbTestClient client(path, 0);
    CHECK(client.width() == 64);
    CHECK(client.wait_for_updates(1, kPatience));
    submit_colour(server, 200);
    CHECK(client.pump_until([&] { return client.frame().row(24)[32 * 4] > 180; }, kPatience));
    std::lock_guard lock(seen_mutex);
    REQUIRE(seen.size() == 1);
    CHECK(seen[0].address == "local");
  }
  CHECK(socket_mode(path) == -1);
}

TEST_CASE("a unix socket server reads PROXY lines as over TCP", "[robustness][unix]") {
  ScratchDir dir("rfbsim_unix");
  const std::string path = dir.path("sim.sock");
  std::mutex mutex;
  std::vector<std::string> addresses;
  rfbsim::ServerOptions options = unix_server(path);
  options.proxy_protocol = true;
  options.on_connect = [&](const rfbsim::ClientInfo& client) {
    std::lock_guard lock(mutex);
    addresses.push_back(client.address);
  };
  rfbsim::Server server(options);
  submit_colour(server, 70);
  const int fd = connect_unix(path);
  REQUIRE(fd >= 0);
  const std::string line = "PROXY TCP4 203.0.113.9 127.0.0.1 40000 5901\r\n";
  REQUIRE(write_all(fd, std::vector<std::uint8_t>(line.begin(), line.end())));
  const rfbsim::test::ReadExact read = [fd](std::size_t n, std::vector<std::uint8_t>& out) {
    return read_exact(fd, n, out);
  };
  const rfbsim::test::WriteAll write = [fd](const std::vector<std::uint8_t>& bytes) { return write_all(fd, bytes); };
  const auto init = rfbsim::test::rfb_client_handshake(read, write);
  CHECK(init.width == 64);
  REQUIRE(write(rfbsim::test::rfb_update_request(false, 0, 0, init.width, init.height)));
  CHECK(!rfbsim::test::rfb_read_raw_update(read, init.bits_per_pixel / 8).empty());
  ::close(fd);
  std::lock_guard lock(mutex);
  REQUIRE(addresses.size() == 1);
  CHECK(addresses[0] == "203.0.113.9");
}

TEST_CASE("a stale socket file is replaced", "[robustness][unix]") {
  ScratchDir dir("rfbsim_unix");
  const std::string path = dir.path("sim.sock");
  make_stale_socket(path);
  REQUIRE(socket_mode(path) >= 0);
  rfbsim::Server server(unix_server(path));
  CHECK(socket_mode(path) == 0600);
  const int fd = connect_unix(path);  // the new socket listens
  CHECK(fd >= 0);
  if (fd >= 0) ::close(fd);
}

TEST_CASE("a live socket is an error, and the server on it still listens", "[robustness][unix]") {
  ScratchDir dir("rfbsim_unix");
  const std::string path = dir.path("sim.sock");
  rfbsim::Server server(unix_server(path));
  REQUIRE(socket_mode(path) == 0600);
  // A second server on the same path would cut the first one off: refused.
  CHECK_THROWS_WITH(rfbsim::Server(unix_server(path)), Catch::Contains("already in use"));
  const int fd = connect_unix(path);  // and the first one still listens
  CHECK(fd >= 0);
  if (fd >= 0) ::close(fd);
}

TEST_CASE("another file at the socket path is an error, and the file is left alone", "[robustness][unix]") {
  ScratchDir dir("rfbsim_unix");
  const std::string file = dir.write("data.csv", "precious\n");
  CHECK_THROWS_WITH(rfbsim::Server(unix_server(file)), Catch::Contains("is not a socket"));
  CHECK(dir.read("data.csv") == "precious\n");
}

TEST_CASE("a socket path too long or in a missing folder is an error", "[robustness][unix]") {
  ScratchDir dir("rfbsim_unix");
  CHECK_THROWS_WITH(rfbsim::Server(unix_server(dir.path(std::string(120, 'x')))), Catch::Contains("bytes long"));
  CHECK_THROWS_WITH(rfbsim::Server(unix_server(dir.path("missing/sim.sock"))), Catch::Contains("cannot bind"));
}

TEST_CASE("sim_rfb --unix-socket: 'ready unix PATH', mode 0600, a client gets a frame, removed at exit",
          "[robustness][unix][process]") {
  ScratchDir dir("rfbsim_unix");
  const std::string path = dir.path("session.sock");
  make_stale_socket(path);  // left by an earlier crash
  int ready[2];
  REQUIRE(::pipe2(ready, O_CLOEXEC) == 0);
  const std::string program = rfbsim::test::sim_rfb_path();
  std::vector<std::string> args = {program, "--unix-socket", path, "--rfb-only", "--ready-fd", "3",
                                   "--width", "160", "--height", "120", "--fps", "10"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::dup2(ready[1], 3);  // dup2 clears close-on-exec on the copy
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::execv(program.c_str(), argv.data());
    _exit(127);
  }
  ::close(ready[1]);
  std::string line;
  pollfd p{ready[0], POLLIN, 0};
  while (line.find('\n') == std::string::npos && ::poll(&p, 1, 30000) == 1) {
    char c = 0;
    if (::read(ready[0], &c, 1) != 1) break;
    line += c;
  }
  CHECK(line == "ready unix " + path + "\n");
  CHECK(socket_mode(path) == 0600);
  {
    rfbsim::test::RfbTestClient client(path, 0);
    CHECK(client.width() == 160);
    CHECK(client.wait_for_updates(1, kPatience));
  }
  ::kill(pid, SIGTERM);
  int status = -1;
  for (int i = 0; i < 1000 && ::waitpid(pid, &status, WNOHANG) == 0; ++i) std::this_thread::sleep_for(10ms);
  if (status == -1) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
  }
  ::close(ready[0]);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(socket_mode(path) == -1);
}

TEST_CASE("sim_rfb refuses --unix-socket together with --port or --bind, and a malformed --allow-origin",
          "[robustness][unix][process]") {
  const std::string program = rfbsim::test::sim_rfb_path();
  const auto both = rfbsim::test::run_to_exit(program, {"--unix-socket", "/tmp/x.sock", "--port", "5901"});
  CHECK(WIFEXITED(both.status));
  CHECK(WEXITSTATUS(both.status) == 2);
  CHECK_THAT(both.output, Catch::Contains("--unix-socket replaces --port and --bind"));
  const auto origin = rfbsim::test::run_to_exit(program, {"--allow-origin", "study.example.org"});
  CHECK(WEXITSTATUS(origin.status) == 2);
  CHECK_THAT(origin.output, Catch::Contains("--allow-origin"));
}
