// SPDX-License-Identifier: GPL-2.0-or-later
// The dial-out RosbridgeClient against LabServer, a stand-in for a lab's rosbridge_server on loopback: the
// bearer token, the advertise and subscribe ops, publishes both ways, reconnecting after the server
// restarts, and wss with a self-signed certificate trusted through ca_file.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <memory>
#include <thread>

#include "eventually.hpp"
#include "lab_server.hpp"
#include "ros/bridge/rosbridge_client.hpp"
#include "scratch_dir.hpp"
#include "tls_test_cert.hpp"

using namespace rfbsim::ros;
using rfbsim::test::eventually;
using rfbsim::test::LabServer;
using rfbsim::test::LabServerOptions;
using std::chrono::milliseconds;
using std::chrono::seconds;

namespace {

void declare_lab_topics(RosbridgeHub& hub) {
  hub.declare("/map", "nav_msgs/msg/OccupancyGrid", true);
  hub.declare("/odom", "nav_msgs/msg/Odometry", false);
  hub.accept("/cmd_vel", {"geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped"});
}

// The received frames from index `from` on, parsed.
std::vector<nlohmann::json> frames_from(const LabServer& server, std::size_t from) {
  std::vector<nlohmann::json> frames;
  const std::vector<std::string> received = server.received();
  for (std::size_t i = from; i < received.size(); ++i) frames.push_back(nlohmann::json::parse(received[i]));
  return frames;
}

bool has_publish(const LabServer& server, std::size_t from, const std::string& topic, const nlohmann::json& msg) {
  for (const nlohmann::json& frame : frames_from(server, from)) {
    if (frame["op"] == "publish" && frame["topic"] == topic && frame["msg"] == msg) return true;
  }
  return false;
}

RosbridgeClientOptions plain_options(int port) {
  RosbridgeClientOptions options;
  options.url = "ws://127.0.0.1:" + std::to_string(port);
  return options;
}

std::vector<IncomingMessage> wait_incoming(RosbridgeHub& hub) {
  std::vector<IncomingMessage> incoming;
  eventually([&] {
    incoming = hub.take_incoming();
    return !incoming.empty();
  });
  return incoming;
}

}  // namespace

TEST_CASE("the client sends its token, advertises and subscribes, and carries publishes both ways") {
  RosbridgeHub hub("/rfbsim/s1");
  declare_lab_topics(hub);
  hub.publish("/map", {{"width", 2}});
  LabServer lab;
  RosbridgeClientOptions options;
  options.url = "ws://127.0.0.1:" + std::to_string(lab.port()) + "/";
  options.token = "s3cret";
  RosbridgeClient client(hub, options);
  REQUIRE(eventually([&] { return client.connected() && lab.received().size() >= 4; }));
  CHECK(lab.authorizations() == std::vector<std::string>{"Bearer s3cret"});

  // The greeting, then the latched /map at once.
  const auto frames = frames_from(lab, 0);
  CHECK(frames[0]["op"] == "advertise");
  CHECK(frames[0]["topic"] == "/rfbsim/s1/map");
  CHECK(frames[0]["type"] == "nav_msgs/OccupancyGrid");
  CHECK(frames[0]["latch"] == true);
  CHECK(frames[1]["op"] == "advertise");
  CHECK(frames[1]["topic"] == "/rfbsim/s1/odom");
  CHECK(frames[2] == nlohmann::json({{"op", "subscribe"}, {"id", "rfbsim_subscribe:/cmd_vel"},
                                     {"topic", "/rfbsim/s1/cmd_vel"}, {"type", "geometry_msgs/Twist"}}));
  CHECK(frames[3] == nlohmann::json({{"op", "publish"}, {"topic", "/rfbsim/s1/map"}, {"msg", {{"width", 2}}}}));

  // Every declared topic is forwarded as the simulation publishes it.
  CHECK(hub.wanted("/odom"));
  hub.publish("/odom", {{"x", 1.5}});
  CHECK(eventually([&] { return has_publish(lab, 4, "/rfbsim/s1/odom", {{"x", 1.5}}); }));

  // The lab's commands arrive as incoming messages.
  lab.send_all(R"({"op":"publish","topic":"/rfbsim/s1/cmd_vel","msg":{"linear":{"x":0.25}}})");
  const auto incoming = wait_incoming(hub);
  REQUIRE(incoming.size() == 1);
  CHECK(incoming[0].topic == "/cmd_vel");
  CHECK(incoming[0].type == "geometry_msgs/msg/Twist");
  CHECK(incoming[0].msg["linear"]["x"] == 0.25);
}

TEST_CASE("the client reconnects after the server restarts and greets it again") {
  RosbridgeHub hub;
  declare_lab_topics(hub);
  hub.publish("/map", {{"width", 5}});
  auto lab = std::make_unique<LabServer>();
  const int port = lab->port();
  RosbridgeClientOptions options;
  options.url = "ws://127.0.0.1:" + std::to_string(port);
  options.max_backoff = milliseconds(1000);
  RosbridgeClient client(hub, options);
  REQUIRE(eventually([&] { return client.connected(); }));
  CHECK(client.connections_opened() == 1);

  lab.reset();  // the lab's server goes away without a close handshake
  REQUIRE(eventually([&] { return !client.connected(); }));
  CHECK(hub.stats().connections == 0);
  // The freed port again; another test running beside this one may hold it a moment, so keep trying.
  REQUIRE(eventually([&] {
    try {
      lab = std::make_unique<LabServer>(LabServerOptions{port, "", ""});
      return true;
    } catch (const std::runtime_error&) {
      return false;
    }
  }));
  REQUIRE(eventually([&] { return client.connected() && lab->received().size() >= 4; }));
  CHECK(client.connections_opened() == 2);
  const auto frames = frames_from(*lab, 0);
  CHECK(frames[0]["op"] == "advertise");
  CHECK(frames[3]["msg"] == nlohmann::json({{"width", 5}}));  // the latched map again
  CHECK(lab->authorizations() == std::vector<std::string>{""});  // no token configured, none sent
}

TEST_CASE("wss: the client verifies the server's certificate through ca_file") {
  rfbsim::test::ScratchDir dir("rfbsim_rosbridge_tls");
  const rfbsim::test::TestCertificate certificate = rfbsim::test::make_test_certificate(dir.path());
  LabServer lab(LabServerOptions{0, certificate.cert_pem.string(), certificate.key_pem.string()});
  RosbridgeHub hub;
  declare_lab_topics(hub);

  SECTION("trusted through ca_file: connects and works") {
    RosbridgeClientOptions options;
    options.url = "wss://127.0.0.1:" + std::to_string(lab.port()) + "/";
    options.ca_file = certificate.cert_pem.string();
    options.token = "t";
    RosbridgeClient client(hub, options);
    REQUIRE(eventually([&] { return client.connected() && lab.received().size() >= 3; }));
    CHECK(lab.authorizations() == std::vector<std::string>{"Bearer t"});
    lab.send_all(R"({"op":"publish","topic":"/cmd_vel","msg":{"linear":{"x":1}}})");
    CHECK(wait_incoming(hub).size() == 1);
  }
  SECTION("not trusted: never connects") {
    RosbridgeClientOptions options;
    options.url = "wss://127.0.0.1:" + std::to_string(lab.port()) + "/";
    RosbridgeClient client(hub, options);
    REQUIRE(eventually([&] { return client.failed_attempts() >= 1; }));  // the first attempt, refused
    CHECK_FALSE(client.connected());
    CHECK(client.connections_opened() == 0);
    CHECK(lab.opened() == 0);
  }
  SECTION("a trusted certificate for another name: never connects") {
    // The openssl CLI makes a self-signed CA certificate for other.example only; the server shows it on
    // 127.0.0.1, so the chain verifies through ca_file and the name check alone refuses it.
    const std::string command = "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:P-256 -nodes "
                                "-subj /CN=other.example -addext subjectAltName=DNS:other.example -days 1 -keyout " +
                                dir.path("other_key.pem") + " -out " + dir.path("other_cert.pem") + " >/dev/null 2>&1";
    REQUIRE(std::system(command.c_str()) == 0);
    LabServer other(LabServerOptions{0, dir.path("other_cert.pem"), dir.path("other_key.pem")});
    RosbridgeClientOptions options;
    options.url = "wss://127.0.0.1:" + std::to_string(other.port()) + "/";
    options.ca_file = dir.path("other_cert.pem");
    RosbridgeClient client(hub, options);
    REQUIRE(eventually([&] { return client.failed_attempts() >= 1; }));
    CHECK_FALSE(client.connected());
    CHECK(client.connections_opened() == 0);
    CHECK(other.opened() == 0);
  }
}

TEST_CASE("the client refuses bad options at construction, naming them") {
  RosbridgeHub hub;
  try {
    RosbridgeClient client(hub, RosbridgeClientOptions{"http://lab:9090", "", "", seconds(1)});
    FAIL("accepted");
  } catch (const std::invalid_argument& error) {
    CHECK(std::string(error.what()).find("http://lab:9090") != std::string::npos);
  }
  CHECK_THROWS_AS(RosbridgeClient(hub, RosbridgeClientOptions{"wss://lab:9090", "", "/no/such/ca.pem"}),
                  std::runtime_error);
  CHECK_THROWS_AS(RosbridgeClient(hub, RosbridgeClientOptions{"ws://lab:9090", "", "/ca.pem"}),
                  std::invalid_argument);
}

TEST_CASE("a client whose server is down keeps retrying quietly and stops at once when destroyed") {
  RosbridgeHub hub;
  declare_lab_topics(hub);
  int port = 0;
  {
    LabServer probe;  // a port that was free a moment ago, now closed
    port = probe.port();
  }
  RosbridgeClientOptions options;
  options.url = "ws://127.0.0.1:" + std::to_string(port);
  auto client = std::make_unique<RosbridgeClient>(hub, options);
  std::this_thread::sleep_for(milliseconds(100));
  CHECK_FALSE(client->connected());
  client.reset();
  CHECK(hub.stats().connections == 0);
}

TEST_CASE("the client pings, and drops and redials a link whose server stops answering") {
  RosbridgeHub hub;
  declare_lab_topics(hub);
  LabServer lab;
  RosbridgeClientOptions options;
  options.url = "ws://127.0.0.1:" + std::to_string(lab.port());
  options.keepalive_interval = milliseconds(50);
  options.pong_timeout = milliseconds(300);
  options.max_backoff = milliseconds(500);
  RosbridgeClient client(hub, options);
  REQUIRE(eventually([&] { return client.connected(); }));
  REQUIRE(eventually([&] { return lab.pings() >= 3; }));
  CHECK(client.connections_opened() == 1);  // answered pings keep the link

  lab.answer_pings(false);  // a link that died without a word: nothing comes back
  REQUIRE(eventually([&] { return client.connections_opened() >= 2; }));
  CHECK(hub.stats().connections <= 1);
}

TEST_CASE("statuses for the dial-out link stay local: the lab's server takes no status op") {
  RosbridgeHub hub;
  declare_lab_topics(hub);
  LabServer lab;
  RosbridgeClient client(hub, plain_options(lab.port()));
  REQUIRE(eventually([&] { return client.connected() && lab.received().size() >= 3; }));
  hub.status(0, "error", "to every connection");
  hub.publish("/odom", {{"marker", 1}});  // queued after the status, so it arrives after it would have
  REQUIRE(eventually([&] { return has_publish(lab, 0, "/odom", {{"marker", 1}}); }));
  for (const nlohmann::json& frame : frames_from(lab, 0)) CHECK(frame["op"] != "status");
}

TEST_CASE("the client sends what the hub still holds before it closes") {
  RosbridgeHub hub;
  declare_lab_topics(hub);
  LabServer lab;
  auto client = std::make_unique<RosbridgeClient>(hub, plain_options(lab.port()));
  REQUIRE(eventually([&] { return client->connected() && lab.received().size() >= 3; }));
  // Far more than the client hands websocketpp at once (256 KiB), then at once the shutdown.
  const std::string pad(50'000, 'p');
  for (int n = 0; n < 40; ++n) hub.publish("/odom", {{"n", n}, {"pad", pad}});
  client.reset();
  CHECK(eventually([&] { return has_publish(lab, 0, "/odom", {{"n", 39}, {"pad", pad}}); }, seconds(5)));
}
