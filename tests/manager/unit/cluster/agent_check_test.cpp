// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>
#include <thread>

#include "cluster/agent_check.hpp"

using rfbsim::manager::agent_status_line;
using rfbsim::manager::AgentCheckServer;
using rfbsim::manager::AgentLoad;

namespace {

namespace asio = boost::asio;

std::string line(int free_slots, int max_slots, bool draining = false, bool shutting_down = false) {
  return agent_status_line(AgentLoad{free_slots, max_slots, draining, shutting_down});
}

// Connects to the agent on loopback, optionally sends `send` first, and reads until the agent closes.
std::string ask(int port, const std::string& send = "") {
  asio::io_context io;
  asio::ip::tcp::socket socket(io);
  socket.connect({asio::ip::make_address_v4("127.0.0.1"), static_cast<unsigned short>(port)});
  if (!send.empty()) asio::write(socket, asio::buffer(send));
  std::string answer;
  boost::system::error_code ec;
  asio::read(socket, asio::dynamic_buffer(answer), ec);  // to end of stream: the agent closes after its line
  CHECK(ec == asio::error::eof);
  return answer;
}

}  // namespace

TEST_CASE("an idle host is ready with its whole weight") {
  CHECK(line(4, 4) == "up ready 100%\n");
  CHECK(line(1, 1) == "up ready 100%\n");
}

TEST_CASE("the weight is the free share of the slots, rounded") {
  CHECK(line(3, 4) == "up ready 75%\n");
  CHECK(line(1, 2) == "up ready 50%\n");
  CHECK(line(1, 3) == "up ready 33%\n");
  CHECK(line(2, 3) == "up ready 67%\n");
  CHECK(line(1, 8) == "up ready 13%\n");  // 12.5 rounds away from zero
}

TEST_CASE("a host with a free slot never reports a weight of 0") {
  CHECK(line(1, 1000) == "up ready 1%\n");
  CHECK(line(1, 10000) == "up ready 1%\n");
}

TEST_CASE("a full, draining or stopping host says drain") {
  CHECK(line(0, 4) == "drain\n");
  CHECK(line(4, 4, true) == "drain\n");
  CHECK(line(4, 4, false, true) == "drain\n");
  CHECK(line(0, 4, true, true) == "drain\n");
}

TEST_CASE("nonsense loads say drain rather than a weight out of range") {
  CHECK(line(-1, 4) == "drain\n");
  CHECK(line(1, 0) == "drain\n");
  CHECK(line(9, 4) == "up ready 100%\n");  // more free than slots (a race in the caller) is capped
}

TEST_CASE("the agent server writes the current line to each connection and closes it") {
  asio::io_context io;
  AgentLoad load{2, 2, false, false};
  int asked = 0;
  AgentCheckServer server(io, "127.0.0.1", 0, [&] {
    ++asked;
    return load;
  });
  REQUIRE(server.port() > 0);
  auto work = asio::make_work_guard(io);
  std::thread runner([&io] { io.run(); });
  // The load is read on the I/O thread for every connection; the test changes it only between connections, and a
  // connection's answer is read to its end before the next change, so the two threads never touch it at once.
  CHECK(ask(server.port()) == "up ready 100%\n");
  asio::post(io, [&] { load.free_slots = 1; });
  CHECK(ask(server.port()) == "up ready 50%\n");
  asio::post(io, [&] { load.draining = true; });
  CHECK(ask(server.port()) == "drain\n");
  // What a peer sends (HAProxy's agent-send, or garbage) is ignored: the answer is the same line.
  CHECK(ask(server.port(), "hello\r\n") == "drain\n");
  asio::post(io, [&] {
    server.stop();
    work.reset();
  });
  runner.join();
  CHECK(asked == 4);
}

TEST_CASE("the agent server names the address it cannot listen on") {
  asio::io_context io;
  AgentCheckServer first(io, "127.0.0.1", 0, [] { return AgentLoad{}; });
  try {
    AgentCheckServer second(io, "127.0.0.1", first.port(), [] { return AgentLoad{}; });
    FAIL("a second listener on the same port was accepted");
  } catch (const std::runtime_error& error) {
    CHECK(std::string(error.what()).find("127.0.0.1:" + std::to_string(first.port())) != std::string::npos);
  }
  CHECK_THROWS_WITH(AgentCheckServer(io, "not-an-address", 0, [] { return AgentLoad{}; }),
                    Catch::Contains("bad address not-an-address"));
}
