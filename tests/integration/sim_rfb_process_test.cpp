// SPDX-License-Identifier: GPL-2.0-or-later
// sim_rfb as a real process: a real RFB client walks the avatar; command-line and setup errors;
// --rfb-only and --ready-fd as sim_manager uses them; each viewer's stream in /status.json and on the ready pipe.
#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>
#include <thread>

#include "raw_socket.hpp"
#include "rfb_test_client.hpp"
#include "rfbsim/server.hpp"
#include "sim_process.hpp"

using namespace std::chrono_literals;
using rfbsim::test::http_body;
using rfbsim::test::http_get;
using rfbsim::test::json_number;
using rfbsim::test::RfbTestClient;
using rfbsim::test::SimProcess;
using rfbsim::test::UpdateMode;

namespace {

std::string status_of(const SimProcess& sim) { return http_body(http_get(sim.port(), "/status.json")); }

// Polls /status.json (while pumping the client, if any) until `done(status)` holds or 10 s pass.
template <typename Done>
bool await_status(const SimProcess& sim, RfbTestClient* client, Done done, std::string& status) {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < deadline) {
    status = status_of(sim);
    if (done(status)) return true;
    if (client != nullptr) client->pump_until([] { return false; }, 50ms);
    else std::this_thread::sleep_for(50ms);  // the sim advances on its own clock
  }
  return false;
}

const std::vector<std::string> kSmall = {"--port", "0", "--width", "320", "--height", "240"};

// The "streams" array of a status document ("" when it has none).
std::string streams_of(const std::string& status) {
  const auto at = status.find("\"streams\":[");
  if (at == std::string::npos) return "";
  const auto end = status.find(']', at);
  return end == std::string::npos ? "" : status.substr(at + 10, end - at - 9);
}

// How many stream objects an array text holds.
std::size_t stream_count(const std::string& streams) {
  std::size_t count = 0;
  for (auto at = streams.find("{\"id\":"); at != std::string::npos; at = streams.find("{\"id\":", at + 1)) ++count;
  return count;
}

// What sim_rfb finds as descriptor 3.
enum class Fd3 {
  kPipe,        // the write end of a pipe whose read end the test holds (what sim_manager does)
  kClosed,      // nothing
  kReaderGone,  // the write end of a pipe whose read end is already closed
};

enum class ReadOutcome { kDone, kEnd, kTimeout };

// Appends what `fd` yields to `text` until `done(text)` holds, the end of the pipe (every writer closed
// it) or `timeout`, and says which came first.
template <typename Done>
ReadOutcome read_until(int fd, std::string& text, Done done, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done(text)) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd pfd{fd, POLLIN, 0};
    if (left.count() <= 0 || ::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) return ReadOutcome::kTimeout;
    char buffer[512];
    const auto n = ::read(fd, buffer, sizeof buffer);
    if (n <= 0) return ReadOutcome::kEnd;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return ReadOutcome::kDone;
}

// Reads `fd` to the end of the pipe within `timeout`; returns whether the end came.
bool read_to_end(int fd, std::string& text, std::chrono::milliseconds timeout) {
  return read_until(fd, text, [](const std::string&) { return false; }, timeout) == ReadOutcome::kEnd;
}

// sim_rfb started the way sim_manager starts it: descriptor 3 set up as `fd3` says, stdout and stderr
// into one pipe (fork, dup2, execv; no shell). SimProcess cannot hand over descriptor 3, and it waits
// for an http:// ready line, which --rfb-only does not print.
class ManagedSim {
 public:
  ManagedSim(const std::vector<std::string>& args, Fd3 fd3) {
    std::vector<std::string> argv_strings{rfbsim::test::sim_rfb_path()};
    argv_strings.insert(argv_strings.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& arg : argv_strings) argv.push_back(arg.data());
    argv.push_back(nullptr);
    int output[2];
    int ready[2];
    REQUIRE(::pipe2(output, O_CLOEXEC) == 0);
    REQUIRE(::pipe2(ready, O_CLOEXEC) == 0);
    pid_ = ::fork();
    REQUIRE(pid_ >= 0);
    if (pid_ == 0) {
      // Only async-signal-safe calls until execv. dup2 clears close-on-exec on the copy, except when
      // the descriptor already is 3; then it is cleared by hand.
      ::dup2(output[1], STDOUT_FILENO);
      ::dup2(output[1], STDERR_FILENO);
      if (fd3 == Fd3::kClosed) {
        ::close(3);
      } else if (ready[1] == 3) {
        ::fcntl(3, F_SETFD, 0);
      } else {
        ::dup2(ready[1], 3);
      }
      ::execv(argv[0], argv.data());
      _exit(127);
    }
    ::close(output[1]);
    ::close(ready[1]);  // sim_rfb holds the only write end: its close is the pipe's end
    output_fd_ = output[0];
    if (fd3 == Fd3::kPipe) {
      ready_fd_ = ready[0];
    } else {
      ::close(ready[0]);
    }
  }
  ~ManagedSim() {
    if (!reaped_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    ::close(output_fd_);
    if (ready_fd_ >= 0) ::close(ready_fd_);
  }
  ManagedSim(const ManagedSim&) = delete;
  ManagedSim& operator=(const ManagedSim&) = delete;

  /// Everything on the ready pipe up to its end (sim_rfb closes it after its line); "" without a pipe.
  std::string ready_pipe(std::chrono::milliseconds timeout = 30s) {
    std::string text;
    if (ready_fd_ >= 0) CHECK(read_to_end(ready_fd_, text, timeout));
    return text;
  }
  /// The ready pipe's first line (the pipe stays open for the outcome line, until sim_rfb ends).
  std::string ready_line(std::chrono::milliseconds timeout = 30s) {
    std::string text;
    if (ready_fd_ >= 0) {
      CHECK(read_until(ready_fd_, text, [](const std::string& t) { return t.find('\n') != std::string::npos; },
                       timeout) == ReadOutcome::kDone);
    }
    return text;
  }
  /// Appends what the ready pipe yields to `text` until `done(text)`, the pipe's end or `timeout`.
  template <typename Done>
  ReadOutcome read_pipe(std::string& text, Done done, std::chrono::milliseconds timeout) {
    REQUIRE(ready_fd_ >= 0);
    return read_until(ready_fd_, text, done, timeout);
  }
  /// Reads stdout and stderr until `pattern` matches them; false on exit or timeout.
  bool await_output(const std::regex& pattern, std::smatch& match, std::chrono::milliseconds timeout = 30s) {
    const auto found = [&](const std::string& text) { return std::regex_search(text, match, pattern); };
    return read_until(output_fd_, output_, found, timeout) == ReadOutcome::kDone;
  }
  /// Sends `signal` (0: none), reads the output to its end and reaps; the wait status, or -1 when
  /// sim_rfb did not exit within `timeout`.
  int exit_status(int signal, std::chrono::milliseconds timeout = 30s) {
    if (signal != 0) ::kill(pid_, signal);
    if (!read_to_end(output_fd_, output_, timeout)) return -1;
    int status = 0;
    ::waitpid(pid_, &status, 0);
    reaped_ = true;
    return status;
  }
  [[nodiscard]] const std::string& output() const { return output_; }

 private:
  pid_t pid_ = -1;
  int output_fd_ = -1;
  int ready_fd_ = -1;
  std::string output_;
  bool reaped_ = false;
};

}  // namespace

TEST_CASE("holding W walks the avatar and changes the picture") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);
  std::string status;
  // Nobody watches yet: the simulation ticks but renders nothing beyond the one frame drawn before it
  // reported ready (so that a viewer's first update is already the scene).
  REQUIRE(await_status(sim, nullptr, [](const std::string& s) { return json_number(s, "tick") > 10; }, status));
  CHECK(json_number(status, "frames_rendered") == 1);
  const double y0 = json_number(status, "y");

  auto client = std::make_unique<RfbTestClient>("127.0.0.1", sim.port());
  REQUIRE(client->width() == 320);
  // Wait for a real picture: the sky above (blue over red) and the floor below.
  REQUIRE(client->pump_until([&] { return client->frame().row(5)[2] > client->frame().row(5)[0] + 20; }, 10s));
  // The standing avatar's picture is static, so no further update is due: this is the reference.
  std::vector<std::uint8_t> before(client->frame().pixels, client->frame().pixels + 320 * 240 * 4);

  client->send_key('w', true);
  REQUIRE(await_status(sim, client.get(), [&](const std::string& s) { return json_number(s, "y") > y0 + 1.0; }, status));
  client->send_key('w', false);
  CHECK(std::abs(json_number(status, "x") - 3.5) < 1e-6);  // straight ahead, along +y
  // The picture follows the walk: the floor tiles slide under the camera.
  CHECK(client->pump_until(
      [&] { return rfbsim::test::mean_abs_difference(client->frame(), {before.data(), 320, 240, 0}) > 5.0; }, 10s));
  REQUIRE(await_status(sim, client.get(), [](const std::string& s) { return json_number(s, "speed") == 0.0; }, status));

  // Disconnect: rendering stops while nobody watches.
  client.reset();
  REQUIRE(await_status(sim, nullptr, [](const std::string& s) { return json_number(s, "clients") == 0; }, status));
  const double frames = json_number(status, "frames_rendered");
  const double tick = json_number(status, "tick");
  CHECK(frames > 0);
  REQUIRE(await_status(sim, nullptr, [&](const std::string& s) { return json_number(s, "tick") > tick + 30; }, status));
  CHECK(json_number(status, "frames_rendered") == frames);

  // Reconnect: a new client gets the picture again.
  RfbTestClient again("127.0.0.1", sim.port());
  CHECK(again.wait_for_updates(1, 10s));

  const int exit_status = sim.stop(SIGTERM);
  REQUIRE(exit_status != -1);
  CHECK(WIFEXITED(exit_status));
  CHECK(WEXITSTATUS(exit_status) == 0);
}

TEST_CASE("/status.json lists each viewer's stream: encoding, ContinuousUpdates, round trip") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);
  std::string status;
  REQUIRE(await_status(sim, nullptr, [](const std::string& s) { return json_number(s, "tick") > 0; }, status));
  CHECK(streams_of(status) == "[]");  // nobody watches

  SECTION("a plain libvncclient client asks for each update: Tight, no ContinuousUpdates, no round trip") {
    RfbTestClient client("127.0.0.1", sim.port());
    REQUIRE(client.wait_for_updates(2, 10s));
    REQUIRE(await_status(sim, &client, [](const std::string& s) {
      return stream_count(streams_of(s)) == 1 && json_number(streams_of(s), "updates_sent") >= 1;
    }, status));
    const std::string streams = streams_of(status);
    INFO(streams);
    CHECK_THAT(streams, Catch::Contains(R"("encoding":"tight")"));
    CHECK_THAT(streams, Catch::Contains(R"("continuous_updates":false)"));
    CHECK_THAT(streams, Catch::Contains(R"("fence":false)"));
    CHECK_THAT(streams, Catch::Contains(R"("last_rtt_ms":null)"));
    CHECK(json_number(streams, "quality") >= 1);
    CHECK(json_number(streams, "quality") <= 100);
    // libvncclient asks for quality level 8 (JPEG 92) and compress level 1: shown as asked, the quality capped.
    CHECK(json_number(streams, "requested_quality_level") == 8);
    CHECK(json_number(streams, "requested_quality") == 92);
    CHECK(json_number(streams, "quality") <= 80);
    CHECK(json_number(streams, "compress_level") == 1);
    // Every key, once.
    for (const char* key : {"id", "encoding", "continuous_updates", "fence", "base_rtt_ms", "last_rtt_ms",
                            "window_bytes", "in_flight_bytes", "updates_sent", "updates_held", "update_requests", "quality",
                            "quality_level", "requested_quality", "requested_quality_level", "compress_level",
                            "delivery_mbit", "fps"}) {
      CHECK(streams.find("\"" + std::string(key) + "\":") != std::string::npos);
    }
  }

  SECTION("a client that speaks ContinuousUpdates and Fence gets pushed updates and a measured round trip") {
    RfbTestClient client("127.0.0.1", sim.port(), 8, UpdateMode::kContinuous);
    REQUIRE(client.pump_until([&] { return client.continuous(); }, 10s));
    client.send_key('w', true);  // a moving picture: updates keep coming, each with its fence
    REQUIRE(await_status(sim, &client, [](const std::string& s) {
      const std::string streams = streams_of(s);
      return streams.find(R"("continuous_updates":true)") != std::string::npos &&
             streams.find(R"("last_rtt_ms":null)") == std::string::npos && json_number(streams, "updates_sent") >= 3;
    }, status));
    client.send_key('w', false);
    const std::string streams = streams_of(status);
    INFO(streams);
    CHECK(stream_count(streams) == 1);
    CHECK_THAT(streams, Catch::Contains(R"("encoding":"tight")"));
    CHECK_THAT(streams, Catch::Contains(R"("fence":true)"));
    CHECK(json_number(streams, "last_rtt_ms") >= 0);
    CHECK(json_number(streams, "base_rtt_ms") >= 0);
    CHECK(client.fences_answered() > 0);
  }
}

TEST_CASE("/status.json names the encoding a client really gets: ZRLE for one that asks for ZRLE only, no quality") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);
  // A raw RFB 3.8 client: security None, a shared ClientInit, then SetEncodings with ZRLE (16) alone and one
  // full update request.
  rfbsim::test::RawSocket client(sim.port());
  REQUIRE(client.read_until("\n", 10s).rfind("RFB 003.00", 0) == 0);
  REQUIRE(client.send_all(std::string("RFB 003.008\n")));
  std::vector<std::uint8_t> bytes;
  REQUIRE(client.read_exact(1, bytes, 10s));
  REQUIRE(client.read_exact(bytes[0], bytes, 10s));  // the security types
  REQUIRE(client.send_all(std::vector<std::uint8_t>{1}));
  REQUIRE(client.read_exact(4, bytes, 10s));  // SecurityResult: OK
  REQUIRE(client.send_all(std::vector<std::uint8_t>{1}));
  REQUIRE(client.read_exact(24, bytes, 10s));  // ServerInit up to the name's length
  const std::uint32_t name_length = (std::uint32_t{bytes[20]} << 24) | (std::uint32_t{bytes[21]} << 16) |
                                    (std::uint32_t{bytes[22]} << 8) | std::uint32_t{bytes[23]};
  REQUIRE(client.read_exact(name_length, bytes, 10s));
  REQUIRE(client.send_all(std::vector<std::uint8_t>{2, 0, 0, 1, 0, 0, 0, 16}));  // SetEncodings: [ZRLE]
  REQUIRE(client.send_all(std::vector<std::uint8_t>{3, 0, 0, 0, 0, 0, 0x01, 0x40, 0, 0xf0}));  // 320x240, full
  std::string status;
  REQUIRE(await_status(sim, nullptr, [](const std::string& s) {
    return stream_count(streams_of(s)) == 1 && json_number(streams_of(s), "updates_sent") >= 1;
  }, status));
  const std::string streams = streams_of(status);
  INFO(streams);
  CHECK_THAT(streams, Catch::Contains(R"("encoding":"zrle")"));
  CHECK(streams.find("\"quality\"") == std::string::npos);  // ZRLE is lossless: no JPEG quality applies
  // The update it got is ZRLE indeed: a FramebufferUpdate whose first rectangle is encoded 16.
  REQUIRE(client.read_exact(16, bytes, 10s));
  CHECK(bytes[0] == 0);  // FramebufferUpdate
  CHECK(((bytes[12] << 24) | (bytes[13] << 16) | (bytes[14] << 8) | bytes[15]) == 16);
}

TEST_CASE("a client that leaves with W held does not leave the avatar walking") {
  SimProcess sim(rfbsim::test::sim_rfb_path(), kSmall);
  std::string status;
  {
    RfbTestClient client("127.0.0.1", sim.port());
    client.send_key('W', true);
    REQUIRE(await_status(sim, &client, [](const std::string& s) { return json_number(s, "speed") > 1.0; }, status));
  }  // gone without releasing W
  REQUIRE(await_status(sim, nullptr, [](const std::string& s) { return json_number(s, "speed") == 0.0; }, status));
  const double y = json_number(status, "y");
  std::string later;
  REQUIRE(await_status(sim, nullptr, [&](const std::string& s) {
    return json_number(s, "tick") > json_number(status, "tick") + 30; }, later));
  CHECK(json_number(later, "y") == y);
}

TEST_CASE("bad command lines and setup failures exit with a clear message") {
  const auto bad_port = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--port", "banana"});
  CHECK(WIFEXITED(bad_port.status));
  CHECK(WEXITSTATUS(bad_port.status) == 2);
  CHECK_THAT(bad_port.output, Catch::Contains("bad value 'banana' for --port"));

  const auto unknown = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--fly"});
  CHECK(WEXITSTATUS(unknown.status) == 2);
  CHECK_THAT(unknown.output, Catch::Contains("unknown argument '--fly'"));

  // The port is taken by another server.
  rfbsim::ServerOptions holder_options;
  holder_options.width = holder_options.height = 64;
  rfbsim::Server holder(holder_options);
  const auto taken = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(),
                                               {"--port", std::to_string(holder.port()), "--width", "320", "--height", "240"});
  CHECK(WEXITSTATUS(taken.status) == 1);
  CHECK_THAT(taken.output, Catch::Contains("port " + std::to_string(holder.port()) + " is already in use"));

  const auto no_page = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--port", "0", "--web-root", "/nonexistent"});
  CHECK(WEXITSTATUS(no_page.status) == 1);
  CHECK_THAT(no_page.output, Catch::Contains("no index.html"));

  // Scenarios: a misspelt name, a bad override and a broken file each end it with 2 and say why.
  const auto unknown_scenario = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(),
                                                          {"--port", "0", "--scenario", "warhouse"});
  CHECK(WEXITSTATUS(unknown_scenario.status) == 2);
  CHECK_THAT(unknown_scenario.output, Catch::Contains("scenario 'warhouse' not found") &&
                                          Catch::Contains("warehouse") && Catch::Contains("lab"));
  const auto bad_start = rfbsim::test::run_to_exit(
      rfbsim::test::sim_rfb_path(), {"--port", "0", "--scenario", "lab", "--avatar-start", "1,2,3,4"});
  CHECK(WEXITSTATUS(bad_start.status) == 2);
  CHECK_THAT(bad_start.output, Catch::Contains("--avatar-start: '1,2,3,4'"));
  const auto broken = std::filesystem::temp_directory_path() / ("rfbsim_broken_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(broken) << "map: lab.yaml\navatar:\n  start: [1, 1]\ncrowd: {count: x}\n";
  const auto broken_file = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(),
                                                     {"--port", "0", "--scenario", broken.string()});
  std::filesystem::remove(broken);
  CHECK(WEXITSTATUS(broken_file.status) == 2);
  CHECK_THAT(broken_file.output, Catch::Contains(broken.string()) && Catch::Contains("key 'map'"));
  CHECK_THAT(broken_file.output, !Catch::Contains("ready"));

  const auto help = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--help"});
  CHECK(WEXITSTATUS(help.status) == 0);
  CHECK_THAT(help.output, Catch::Contains("usage: sim_rfb"));
}

TEST_CASE("sim_rfb --rfb-only --ready-fd 3 reports the port on the pipe and serves RFB, not HTTP") {
  std::vector<std::string> args = kSmall;
  args.insert(args.end(), {"--rfb-only", "--ready-fd", "3"});
  ManagedSim sim(args, Fd3::kPipe);

  // One line; the pipe stays open for the task's outcome, and closes when sim_rfb ends.
  const std::string ready = sim.ready_line();
  std::smatch ready_match;
  REQUIRE(std::regex_match(ready, ready_match, std::regex("ready ([0-9]+)\n")));
  const int port = std::stoi(ready_match[1]);
  CHECK(port > 0);
  // The stdout line is still printed, naming the same port; without a page it is an RFB address.
  std::smatch stdout_match;
  REQUIRE(sim.await_output(std::regex(R"(sim_rfb ready: vnc://127\.0\.0\.1:([0-9]+)\n)"), stdout_match));
  CHECK(std::stoi(stdout_match[1]) == port);

  {
    RfbTestClient client("127.0.0.1", port);
    CHECK(client.width() == 320);
    CHECK(client.wait_for_updates(1, 10s));
  }

  // No page and no status: a plain GET is dropped like a bad RFB client, and RFB is served on.
  const std::string response = http_get(port, "/status.json");
  CHECK(response.find("HTTP/1.1 200") == std::string::npos);
  CHECK(response.find("\"tick\"") == std::string::npos);
  RfbTestClient again("127.0.0.1", port);
  CHECK(again.wait_for_updates(1, 10s));

  const int exit_status = sim.exit_status(SIGTERM);
  REQUIRE(exit_status != -1);
  CHECK(WIFEXITED(exit_status));
  CHECK(WEXITSTATUS(exit_status) == 0);
  // The built-in room has no task, so no outcome followed the ready line before the pipe closed; the viewers'
  // stream lines may have, if one of them stayed a second.
  const std::string rest = sim.ready_pipe();
  CHECK(std::regex_match(rest, std::regex("(stream [^\n]*\n)*")));
}

TEST_CASE("sim_rfb tells its parent the viewer's stream on the ready pipe about once a second") {
  std::vector<std::string> args = kSmall;
  args.insert(args.end(), {"--rfb-only", "--ready-fd", "3", "--fps", "20"});
  ManagedSim sim(args, Fd3::kPipe);
  std::smatch ready_match;
  const std::string ready = sim.ready_line();
  REQUIRE(std::regex_match(ready, ready_match, std::regex("ready ([0-9]+)\n")));

  // Pumps the client while reading the pipe, until a line matching `pattern` has come; the lines so far.
  const auto await_line = [&](RfbTestClient* client, const std::regex& pattern, std::string& lines) {
    const auto deadline = std::chrono::steady_clock::now() + 15s;
    const auto found = [&](const std::string& text) { return std::regex_search(text, pattern); };
    while (std::chrono::steady_clock::now() < deadline) {
      if (client != nullptr) client->pump_until([] { return false; }, 50ms);
      if (sim.read_pipe(lines, found, 50ms) == ReadOutcome::kDone) return true;
    }
    return false;
  };
  std::string lines;
  {
    RfbTestClient client("127.0.0.1", std::stoi(ready_match[1]));
    client.send_key('w', true);  // a moving picture, so that updates keep coming
    // The participant's stream: libvncclient asks for each update, so Tight and no measured round trip; it asks
    // for quality level 8 (requested=92), above the server's 80.
    const std::regex watched(
        R"(stream codec=tight rtt_ms=-1 fps=([0-9]+\.[0-9]) quality=([0-9]+) requested=([0-9]+) clients=1
)");
    REQUIRE(await_line(&client, watched, lines));
    // A second later, another.
    const auto first = std::chrono::steady_clock::now();
    std::string more;
    REQUIRE(await_line(&client, watched, more));
    const double gap = std::chrono::duration<double>(std::chrono::steady_clock::now() - first).count();
    CHECK(gap > 0.5);
    CHECK(gap < 3.0);
    std::smatch match;
    REQUIRE(std::regex_search(more, match, watched));
    CHECK(std::stod(match[1]) > 0.0);   // updates flow
    CHECK(std::stod(match[1]) <= 40.0);  // about the frame rate (20), give or take the second's edges
    CHECK(std::stoi(match[2]) == 80);    // the default quality
    CHECK(std::stoi(match[3]) == 92);    // level 8 through libvncserver's table: capped by the 80
    lines += more;
    client.send_key('w', false);
  }
  // The viewer left: one line says so.
  std::string after;
  REQUIRE(await_line(nullptr, std::regex("stream clients=0\n"), after));
  lines += after;
  // Every line on the pipe is a stream line, each short enough for one atomic write.
  std::istringstream in(lines);
  for (std::string line; std::getline(in, line);) {
    CHECK(line.rfind("stream ", 0) == 0);
    CHECK(line.size() < 100);
  }
  const int exit_status = sim.exit_status(SIGTERM);
  CHECK(WIFEXITED(exit_status));
  CHECK(WEXITSTATUS(exit_status) == 0);
}

TEST_CASE("a ready fd that cannot be written ends sim_rfb with 1 and says why") {
  const std::vector<std::string> args = {"--port", "0", "--width", "320", "--height", "240", "--rfb-only",
                                         "--ready-fd", "3"};
  SECTION("descriptor 3 is not open") {
    ManagedSim sim(args, Fd3::kClosed);
    const int exit_status = sim.exit_status(0);
    REQUIRE(exit_status != -1);
    CHECK(WIFEXITED(exit_status));
    CHECK(WEXITSTATUS(exit_status) == 1);
    CHECK_THAT(sim.output(), Catch::Contains("--ready-fd 3: not an open file descriptor"));
    CHECK_THAT(sim.output(), !Catch::Contains("sim_rfb ready"));
  }
  SECTION("the pipe's reader is gone: EPIPE, not a silent SIGPIPE") {
    ManagedSim sim(args, Fd3::kReaderGone);
    const int exit_status = sim.exit_status(0);
    REQUIRE(exit_status != -1);
    CHECK_FALSE(WIFSIGNALED(exit_status));
    CHECK(WIFEXITED(exit_status));
    CHECK(WEXITSTATUS(exit_status) == 1);
    CHECK_THAT(sim.output(), Catch::Contains("--ready-fd 3: cannot write the ready line (Broken pipe)"));
    CHECK_THAT(sim.output(), !Catch::Contains("sim_rfb ready"));
  }
  SECTION("0, 1 and 2 are refused as bad arguments") {
    const auto stderr_fd = rfbsim::test::run_to_exit(rfbsim::test::sim_rfb_path(), {"--ready-fd", "2"});
    CHECK(WIFEXITED(stderr_fd.status));
    CHECK(WEXITSTATUS(stderr_fd.status) == 2);
    CHECK_THAT(stderr_fd.output, Catch::Contains("bad value '2' for --ready-fd"));
  }
}
