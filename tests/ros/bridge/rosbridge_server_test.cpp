// SPDX-License-Identifier: GPL-2.0-or-later
// A real RosbridgeServer on a loopback port with real WebSocket clients (TestWsClient writes the frames):
// subscribe and publish end to end, errors that leave the connection open, an oversized message that
// closes it, paths and connection limits (and their log lines), and a client that never reads.
#include <catch2/catch.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "eventually.hpp"
#include "rfbsim/log.hpp"
#include "ros/bridge/rosbridge_server.hpp"
#include "test_ws_client.hpp"

using namespace rfbsim::ros;
using rfbsim::test::eventually;
using rfbsim::test::TestWsClient;
using std::chrono::milliseconds;
using std::chrono::seconds;

namespace {

void declare_served_topics(RosbridgeHub& hub) {
  hub.declare("/scan", "sensor_msgs/msg/LaserScan", false);
  hub.declare("/map", "nav_msgs/msg/OccupancyGrid", true);
  hub.accept("/cmd_vel", {"geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped"});
}

// A TCP connection to 127.0.0.1:`port` that sends nothing (a half-open WebSocket); -1 when refused.
int raw_connection(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

auto op_is(const std::string& op) {
  return [op](const nlohmann::json& value) { return value.value("op", "") == op; };
}

// Subscribes `client` to `topic` and waits for the server's "subscribed" (an info status, asked for just
// for this), so that a publish after it cannot be lost.
void subscribe(TestWsClient& client, const std::string& topic) {
  client.send_json({{"op", "set_level"}, {"level", "info"}});
  client.send_json({{"op", "subscribe"}, {"id", "sub:" + topic}, {"topic", topic}});
  REQUIRE(client.wait_for([&](const nlohmann::json& value) {
    return value.value("op", "") == "status" && value.value("id", "") == "sub:" + topic;
  }));
  client.send_json({{"op", "set_level"}, {"level", "warning"}});
}

// Server options with a message limit of 1000 bytes.
RosbridgeServerOptions oversize_limited_options() {
  RosbridgeServerOptions options;
  options.max_message_bytes = 1000;
  return options;
}

// Sends `client` a publish of about 2 KB (over oversize_limited_options' limit) and reads on to the close
// frame; the first status it got, if any.
std::optional<nlohmann::json> send_oversized_publish(TestWsClient& client) {
  const std::string big = R"({"op":"publish","topic":"/cmd_vel","msg":{"pad":")" + std::string(2000, 'x') + "\"}}";
  client.send(big);
  const auto status = client.wait_for(op_is("status"));
  while (client.read_frame(seconds(5))) {}  // to the close frame
  return status;
}

// Sends `client` a 20 KB message, far over oversize_limited_options' limit, and reads on to the close frame.
void send_far_oversized(TestWsClient& client) {
  // Far over the limit: websocketpp refuses it itself while reading, with the same close code.
  client.send(std::string(20'000, ' '));
  while (client.read_frame(seconds(5))) {}
}

}  // namespace

TEST_CASE("a subscriber gets the simulation's publishes and a publish to /cmd_vel reaches the simulation") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  hub.publish("/map", {{"info", {{"width", 4}}}});
  RosbridgeServer server(hub, {});
  REQUIRE(server.port() > 0);
  TestWsClient client(server.port());

  client.send_json({{"op", "subscribe"}, {"topic", "/map"}});
  const auto map = client.wait_for(op_is("publish"));
  REQUIRE(map);
  CHECK((*map)["topic"] == "/map");
  CHECK((*map)["msg"]["info"]["width"] == 4);

  subscribe(client, "/scan");
  hub.publish("/scan", {{"ranges", {1.5, 2.5}}});
  const auto scan = client.wait_for(op_is("publish"));
  REQUIRE(scan);
  CHECK((*scan)["topic"] == "/scan");
  CHECK((*scan)["msg"]["ranges"][1] == 2.5);

  client.send_json({{"op", "advertise"}, {"topic", "/cmd_vel"}, {"type", "geometry_msgs/TwistStamped"}});
  nlohmann::json stamped;
  stamped["header"]["frame_id"] = "base_link";
  stamped["twist"]["linear"]["x"] = 0.3;
  client.send_json({{"op", "publish"}, {"topic", "/cmd_vel"}, {"msg", stamped}});
  std::vector<IncomingMessage> incoming;
  REQUIRE(eventually([&] {
    for (IncomingMessage& message : hub.take_incoming()) incoming.push_back(std::move(message));
    return !incoming.empty();
  }));
  CHECK(incoming[0].topic == "/cmd_vel");
  CHECK(incoming[0].type == "geometry_msgs/msg/TwistStamped");
  CHECK(incoming[0].msg["twist"]["linear"]["x"] == 0.3);
  CHECK(server.stats().opened == 1);
}

TEST_CASE("bad input gets an error status and the connection stays open") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServer server(hub, {});
  TestWsClient client(server.port());
  const auto error_with_id = [](const std::string& id) {
    return [id](const nlohmann::json& value) {
      return value.value("op", "") == "status" && value.value("level", "") == "error" && value.value("id", "") == id;
    };
  };
  client.send("{\"op\":\"subscribe\",");  // malformed: no id to echo
  const auto malformed = client.wait_for(op_is("status"));
  REQUIRE(malformed);
  CHECK((*malformed)["level"] == "error");
  client.send_json({{"op", "jump"}, {"id", "u"}});
  CHECK(client.wait_for(error_with_id("u")));
  client.send_json({{"op", "subscribe"}, {"id", "m"}});
  CHECK(client.wait_for(error_with_id("m")));
  client.send_json({{"op", "subscribe"}, {"id", "w"}, {"topic", "/scan"}, {"type", "std_msgs/String"}});
  CHECK(client.wait_for(error_with_id("w")));
  client.send("\x01\x02", 2);  // binary (CBOR) is refused, not fatal
  CHECK(client.wait_for(op_is("status")));

  // Still serving: a subscription works after all that.
  subscribe(client, "/scan");
  hub.publish("/scan", {{"ranges", {1.0}}});
  CHECK(client.wait_for(op_is("publish")));
}

TEST_CASE("an oversized message gets an error status and a close with 1009") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServer server(hub, oversize_limited_options());
  TestWsClient client(server.port());
  const auto status = send_oversized_publish(client);
  REQUIRE(status);
  CHECK((*status)["level"] == "error");
  CHECK((*status)["msg"].get<std::string>().find("over the limit") != std::string::npos);
  CHECK(client.close_code() == 1009);
  CHECK(hub.take_incoming().empty());
  CHECK(eventually([&] { return server.stats().closed_oversized == 1; }));
}

TEST_CASE("a message far over the limit is refused while it is read, with a close with 1009") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServer server(hub, oversize_limited_options());
  TestWsClient client(server.port());
  send_far_oversized(client);
  CHECK(client.close_code() == 1009);
  CHECK(hub.take_incoming().empty());
  CHECK(server.stats().closed_oversized == 0);  // websocketpp's refusal: the server never saw the message
}

TEST_CASE("after oversized messages closed their clients, a second client is served") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServer server(hub, oversize_limited_options());
  {
    TestWsClient client(server.port());
    REQUIRE(send_oversized_publish(client));
    REQUIRE(client.close_code() == 1009);
  }
  {
    TestWsClient client(server.port());
    send_far_oversized(client);
    REQUIRE(client.close_code() == 1009);
  }
  TestWsClient second(server.port());
  subscribe(second, "/scan");
  hub.publish("/scan", {{"ranges", {1.0}}});
  CHECK(second.wait_for(op_is("publish")));
  CHECK(server.stats().closed_oversized == 1);
}

TEST_CASE("the WebSocket is at / only, and connections beyond the limit are refused") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServerOptions options;
  options.max_connections = 2;
  RosbridgeServer server(hub, options);
  CHECK(TestWsClient::handshake_status(server.port(), "/other") == 404);
  CHECK(TestWsClient::handshake_status(server.port(), "/?x=1") == 101);
  CHECK(TestWsClient::handshake_status(server.port(), "/", false) == 426);
  CHECK(TestWsClient::handshake_status(server.port(), "/x", false) == 404);
  REQUIRE(eventually([&] { return server.stats().open == 0; }));
  {
    TestWsClient one(server.port());
    TestWsClient two(server.port());
    CHECK(TestWsClient::handshake_status(server.port(), "/") == 503);
  }
  REQUIRE(eventually([&] { return server.stats().open == 0; }));
  CHECK(TestWsClient::handshake_status(server.port(), "/") == 101);
}

TEST_CASE("refusals a client causes are logged, rate-limited by kind, naming no address") {
  rfbsim::log::flush_suppressed();  // counts left by earlier tests go out before the capture starts
  std::mutex mutex;
  std::vector<std::string> lines;
  rfbsim::log::set_sink([&](std::string_view line) {
    const std::lock_guard lock(mutex);
    lines.emplace_back(line);
  });
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServerOptions options;
  options.max_connections = 1;
  {
    RosbridgeServer server(hub, options);
    TestWsClient one(server.port());
    for (int n = 0; n < 30; ++n) CHECK(TestWsClient::handshake_status(server.port(), "/") == 503);
  }
  rfbsim::log::flush_suppressed();
  rfbsim::log::set_sink({});

  // Each refusal is either a line or counted in the one "suppressed" line that follows them.
  long long written = 0;
  long long suppressed = 0;
  for (const std::string& line : lines) {
    CHECK(line.find("127.0.0.1") == std::string::npos);
    if (line.find("refused a connection (503): at the limit of 1 connections") != std::string::npos) ++written;
    const auto at = line.find(" more like this suppressed (rosbridge-connection-limit)");
    const auto from = line.find("] ") + 2;  // after the tag
    if (at != std::string::npos) suppressed += std::stoll(line.substr(from, at - from));
  }
  CHECK(written >= 1);
  CHECK(written <= 5);  // the log's default budget: 5 lines per kind per 10 s
  CHECK(written + suppressed == 30);
}

TEST_CASE("a client that never reads loses its oldest messages, not the server's memory") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServerOptions options;
  options.max_queued_bytes_per_connection = 64 << 10;
  RosbridgeServer server(hub, options);
  TestWsClient stalled(server.port(), "/", 4096);
  subscribe(stalled, "/scan");

  // 40 MB published; the socket buffers take a few MB, the hub at most 64 KiB; the rest is dropped.
  const std::vector<double> ranges(1000, 3.25);
  for (int n = 0; n < 4000; ++n) hub.publish("/scan", {{"n", n}, {"ranges", ranges}});
  REQUIRE(eventually([&] { return hub.stats().dropped_frames > 0; }));
  const std::size_t frame_bytes = nlohmann::json({{"n", 0}, {"ranges", ranges}}).dump().size() + 64;
  CHECK(hub.stats().peak_queued_bytes <= (64u << 10) + frame_bytes);

  // Meanwhile another client is served at once.
  TestWsClient fresh(server.port());
  subscribe(fresh, "/scan");
  hub.publish("/scan", {{"n", -1}});
  const auto got = fresh.wait_for([](const nlohmann::json& value) { return value.value("op", "") == "publish"; });
  REQUIRE(got);
  CHECK((*got)["msg"]["n"] == -1);
}

TEST_CASE("the server stops cleanly with clients connected and forgets its hub connections") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  auto server = std::make_unique<RosbridgeServer>(hub, RosbridgeServerOptions{});
  TestWsClient client(server->port());
  subscribe(client, "/scan");
  server.reset();
  CHECK(hub.stats().connections == 0);
  CHECK_FALSE(hub.wanted("/scan"));
  while (client.read_frame(seconds(5))) {}
  CHECK(client.close_code() == 1001);
  CHECK_THROWS_AS(RosbridgeServer(hub, RosbridgeServerOptions{"not an address", 0}), std::invalid_argument);
}

TEST_CASE("accepted sockets that never finish a handshake are capped at 4 x max_connections") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServerOptions options;
  options.max_connections = 2;
  RosbridgeServer server(hub, options);
  std::vector<int> half_open;
  for (int n = 0; n < 12; ++n) half_open.push_back(raw_connection(server.port()));
  CHECK(std::count(half_open.begin(), half_open.end(), -1) == 0);  // the kernel accepts; the server closes
  REQUIRE(eventually([&] { return server.stats().sockets_refused == 4; }));
  for (const int fd : half_open) ::close(fd);
  // Once they are gone, the slots are free again.
  CHECK(eventually([&] { return TestWsClient::handshake_status(server.port(), "/") == 101; }));
  CHECK(server.stats().sockets_refused >= 4);
}

TEST_CASE("the server hands each client what the hub still holds before it closes") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  auto server = std::make_unique<RosbridgeServer>(hub, RosbridgeServerOptions{});
  TestWsClient client(server->port());
  subscribe(client, "/scan");
  // Far more than the server hands websocketpp at once (256 KiB), all queued in the hub at shutdown.
  const std::string pad(50'000, 'p');
  for (int n = 0; n < 40; ++n) hub.publish("/scan", {{"n", n}, {"pad", pad}});
  // The client reads while the server shuts down, as a live one would.
  std::thread stop([&server] { server.reset(); });
  int last = -1;
  while (const auto frame = client.read_frame(seconds(5))) {
    if (frame->opcode != 1) continue;
    const auto value = nlohmann::json::parse(frame->payload);
    if (value.value("op", "") == "publish") last = value["msg"]["n"];
  }
  stop.join();
  CHECK(last == 39);
  CHECK(client.close_code() == 1001);
}

TEST_CASE("the oversized-message status overtakes a backlog and comes before the 1009 close") {
  RosbridgeHub hub;
  declare_served_topics(hub);
  RosbridgeServerOptions options;
  options.max_message_bytes = 1000;
  RosbridgeServer server(hub, options);
  TestWsClient client(server.port(), "/", 4096);
  subscribe(client, "/scan");
  // A backlog: the socket and websocketpp's buffer full, more waiting in the hub.
  const std::string pad(50'000, 'p');
  for (int n = 0; n < 100; ++n) hub.publish("/scan", {{"n", n}, {"pad", pad}});
  REQUIRE(eventually([&] { return hub.stats().peak_queued_bytes > (1u << 20); }));
  client.send(R"({"op":"publish","topic":"/cmd_vel","msg":{"pad":")" + std::string(2000, 'x') + "\"}}");
  bool status_seen = false;
  while (const auto frame = client.read_frame(seconds(5))) {
    if (frame->opcode != 1) continue;
    const auto value = nlohmann::json::parse(frame->payload);
    if (value.value("op", "") != "status") continue;
    if (value.value("msg", "").find("over the limit") != std::string::npos) status_seen = true;
  }
  CHECK(status_seen);
  CHECK(client.close_code() == 1009);
}
