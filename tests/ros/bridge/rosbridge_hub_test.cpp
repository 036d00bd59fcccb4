// SPDX-License-Identifier: GPL-2.0-or-later
// RosbridgeHub without a network, on a fake clock: fan-out, latched topics, throttle_rate and
// queue_length, merged subscriptions, the dial-out mirror, status levels and the bounds on memory.
#include <catch2/catch.hpp>

#include <stdexcept>

#include "ros/bridge/rosbridge_hub.hpp"

using namespace rfbsim::ros;
using Clock = RosbridgeHub::Clock;
using std::chrono::milliseconds;

namespace {

// A hub on a clock the test moves by hand.
struct FakeClockHub {
  Clock::time_point now{};
  RosbridgeHub hub{"", [this] { return now; }};
};

// Every frame waiting for `connection`, parsed.
std::vector<nlohmann::json> drain(RosbridgeHub& hub, int connection) {
  std::vector<nlohmann::json> frames;
  for (const Frame& frame : hub.take_outgoing(connection, SIZE_MAX)) frames.push_back(nlohmann::json::parse(*frame));
  return frames;
}

nlohmann::json counter(int n) { return {{"data", n}}; }

// Nine topics, /t0 to /t8: more than the 256 subscriptions a connection may hold, at 32 per topic.
void declare_capped_topics(RosbridgeHub& hub) {
  for (int t = 0; t < 9; ++t) hub.declare("/t" + std::to_string(t), "std_msgs/Int32", false);
}

// Subscription id "id`n`", with no throttle and no queue length.
SubscribeOptions capped_id(int n) { return SubscribeOptions{"id" + std::to_string(n), 0, 0}; }

}  // namespace

TEST_CASE("declare and accept check their names and types") {
  RosbridgeHub hub;
  hub.declare("/scan", "sensor_msgs/LaserScan", false);
  CHECK(hub.declared("/scan")->type == "sensor_msgs/msg/LaserScan");
  hub.accept("cmd_vel", {"geometry_msgs/Twist", "geometry_msgs/msg/TwistStamped"});
  CHECK(hub.accepted("/cmd_vel")->types == std::vector<std::string>{"geometry_msgs/msg/Twist",
                                                                     "geometry_msgs/msg/TwistStamped"});
  CHECK_THROWS_AS(hub.declare("/scan", "sensor_msgs/LaserScan", false), std::invalid_argument);
  CHECK_THROWS_AS(hub.declare("/cmd_vel", "geometry_msgs/Twist", false), std::invalid_argument);
  CHECK_THROWS_AS(hub.declare("/bad topic", "std_msgs/String", false), std::invalid_argument);
  CHECK_THROWS_AS(hub.declare("/x", "String", false), std::invalid_argument);
  CHECK_THROWS_AS(hub.accept("/y", {}), std::invalid_argument);
  CHECK_THROWS_AS(hub.publish("/nope", counter(1)), std::invalid_argument);
  CHECK_THROWS_AS(RosbridgeHub("no_slash"), std::invalid_argument);
}

TEST_CASE("a publish reaches every subscriber of its topic and nobody else") {
  FakeClockHub f;
  f.hub.declare("/a", "std_msgs/Int32", false);
  f.hub.declare("/b", "std_msgs/Int32", false);
  CHECK_FALSE(f.hub.wanted("/a"));
  const int one = f.hub.open_connection({});
  const int two = f.hub.open_connection({});
  f.hub.subscribe(one, "/a", {});
  f.hub.subscribe(two, "/a", {});
  f.hub.subscribe(two, "/b", {});
  CHECK(f.hub.wanted("/a"));
  f.hub.publish("/a", counter(1));
  f.hub.publish("/b", counter(2));
  const auto first = drain(f.hub, one);
  REQUIRE(first.size() == 1);
  CHECK(first[0] == nlohmann::json({{"op", "publish"}, {"topic", "/a"}, {"msg", counter(1)}}));
  CHECK(drain(f.hub, two).size() == 2);

  CHECK(f.hub.unsubscribe(one, "/a", ""));
  CHECK_FALSE(f.hub.unsubscribe(one, "/a", ""));
  f.hub.publish("/a", counter(3));
  CHECK(drain(f.hub, one).empty());
  f.hub.close_connection(two);
  CHECK_FALSE(f.hub.wanted("/a"));
}

TEST_CASE("a namespaced hub prefixes every wire topic and strips it from incoming names") {
  RosbridgeHub hub("/rfbsim/s1/");
  hub.declare("/odom", "nav_msgs/Odometry", false);
  CHECK(hub.wire_topic("/odom") == "/rfbsim/s1/odom");
  CHECK(hub.local_topic("/rfbsim/s1/cmd_vel") == "/cmd_vel");
  CHECK(hub.local_topic("rfbsim/s1/cmd_vel") == "/cmd_vel");
  CHECK_FALSE(hub.local_topic("/cmd_vel"));
  CHECK_FALSE(hub.local_topic("/rfbsim/s10/cmd_vel"));
  CHECK_FALSE(hub.local_topic("/rfbsim/s1"));
  const int connection = hub.open_connection({});
  hub.subscribe(connection, "/odom", {});
  hub.publish("/odom", counter(7));
  CHECK(drain(hub, connection).at(0)["topic"] == "/rfbsim/s1/odom");
}

TEST_CASE("a latched topic's last message goes to each new subscriber and to a dial-out link at once") {
  FakeClockHub f;
  f.hub.declare("/map", "nav_msgs/OccupancyGrid", true);
  f.hub.declare("/clock", "rosgraph_msgs/Clock", false);
  CHECK(f.hub.wanted("/map"));  // always: later subscribers need it
  f.hub.publish("/map", counter(1));
  f.hub.publish("/map", counter(2));
  f.hub.publish("/clock", counter(9));  // not latched, nobody listening: gone

  const int late = f.hub.open_connection({});
  f.hub.subscribe(late, "/map", {});
  f.hub.subscribe(late, "/clock", {});
  const auto frames = drain(f.hub, late);
  REQUIRE(frames.size() == 1);
  CHECK(frames[0]["msg"] == counter(2));

  HubConnectionOptions mirror;
  mirror.mirror_declared = true;
  mirror.greeting = {R"({"op":"advertise"})"};
  const int link = f.hub.open_connection(mirror);
  CHECK(f.hub.is_dial_out(link));
  CHECK_FALSE(f.hub.is_dial_out(late));
  CHECK_FALSE(f.hub.is_dial_out(0));
  const auto linked = drain(f.hub, link);
  REQUIRE(linked.size() == 2);
  CHECK(linked[0]["op"] == "advertise");  // the greeting first
  CHECK(linked[1]["msg"] == counter(2));
  f.hub.publish("/clock", counter(10));  // a mirror takes every declared topic
  CHECK(drain(f.hub, link).at(0)["msg"] == counter(10));
}

TEST_CASE("throttle_rate without a queue drops what comes too soon") {
  FakeClockHub f;
  f.hub.declare("/scan", "sensor_msgs/LaserScan", false);
  const int connection = f.hub.open_connection({});
  f.hub.subscribe(connection, "/scan", SubscribeOptions{"", 100, 0});
  for (int tick = 0; tick < 10; ++tick) {  // 10 messages, 40 ms apart: sent at 0, 120, 240, 360 ms
    f.hub.publish("/scan", counter(tick));
    f.now += milliseconds(40);
  }
  std::vector<int> sent;
  for (const auto& frame : drain(f.hub, connection)) sent.push_back(frame["msg"]["data"]);
  CHECK(sent == std::vector<int>{0, 3, 6, 9});
  CHECK(f.hub.stats().throttled_frames == 6);
}

TEST_CASE("throttle_rate with a queue holds the newest queue_length messages and releases them in time") {
  FakeClockHub f;
  f.hub.declare("/scan", "sensor_msgs/LaserScan", false);
  const int connection = f.hub.open_connection({});
  f.hub.subscribe(connection, "/scan", SubscribeOptions{"s", 100, 2});
  for (int n = 0; n < 5; ++n) f.hub.publish("/scan", counter(n));  // all at t = 0
  CHECK(drain(f.hub, connection).size() == 1);                     // 0 now; 3 and 4 held, 1 and 2 pushed out
  CHECK(f.hub.flush_due() == f.now + milliseconds(100));
  f.now += milliseconds(99);
  CHECK(f.hub.flush_due() == Clock::time_point{} + milliseconds(100));
  CHECK(drain(f.hub, connection).empty());
  f.now += milliseconds(1);
  f.hub.flush_due();
  CHECK(drain(f.hub, connection).at(0)["msg"] == counter(3));
  f.now += milliseconds(100);
  CHECK_FALSE(f.hub.flush_due());  // the last one went; nothing waits
  CHECK(drain(f.hub, connection).at(0)["msg"] == counter(4));
}

TEST_CASE("a queue_length over kMaxQueueLength holds kMaxQueueLength messages behind the throttle") {
  FakeClockHub f;
  f.hub.declare("/tf", "tf2_msgs/TFMessage", false);
  const int connection = f.hub.open_connection({});
  // An hour's throttle with a queue of 10^9: uncut, it would keep every publish for the hour.
  CHECK(f.hub.subscribe(connection, "/tf", SubscribeOptions{"greedy", 3'600'000, 1'000'000'000}).empty());
  for (int n = 0; n < 1000; ++n) f.hub.publish("/tf", counter(n));  // all at t = 0
  CHECK(drain(f.hub, connection).size() == 1);                      // 0 goes at once
  const std::size_t held = RosbridgeHub::kMaxQueueLength;
  CHECK(f.hub.stats().throttled_frames == 1000 - 1 - held);         // 1 .. 899 gave way
  // The held ones come out one per throttle period, the oldest kept first.
  f.now += milliseconds(3'600'000);
  f.hub.flush_due();
  CHECK(drain(f.hub, connection).at(0)["msg"] == counter(1000 - static_cast<int>(held)));
}

TEST_CASE("several subscriptions to one topic send at the lowest throttle and the longest queue") {
  FakeClockHub f;
  f.hub.declare("/odom", "nav_msgs/Odometry", false);
  const int connection = f.hub.open_connection({});
  f.hub.subscribe(connection, "/odom", SubscribeOptions{"slow", 1000, 0});
  f.hub.subscribe(connection, "/odom", SubscribeOptions{"fast", 0, 0});
  f.hub.publish("/odom", counter(1));
  f.hub.publish("/odom", counter(2));
  CHECK(drain(f.hub, connection).size() == 2);
  CHECK(f.hub.unsubscribe(connection, "/odom", "fast"));  // back to 1 s
  CHECK_FALSE(f.hub.unsubscribe(connection, "/odom", "fast"));
  f.hub.publish("/odom", counter(3));
  CHECK(drain(f.hub, connection).empty());
}

TEST_CASE("status messages honour each connection's level") {
  RosbridgeHub hub;
  const int one = hub.open_connection({});
  const int two = hub.open_connection({});
  hub.status(0, "warning", "to all", "op1");
  hub.status(one, "info", "info is muted by default", "");
  auto frames = drain(hub, one);
  REQUIRE(frames.size() == 1);
  CHECK(frames[0] == nlohmann::json({{"op", "status"}, {"level", "warning"}, {"msg", "to all"}, {"id", "op1"}}));
  CHECK(drain(hub, two).size() == 1);
  hub.set_level(two, StatusLevel::kError);
  hub.status(two, "warning", "muted", "");
  hub.status(two, "error", "heard", "");
  frames = drain(hub, two);
  REQUIRE(frames.size() == 1);
  CHECK(frames[0]["msg"] == "heard");
  CHECK_FALSE(frames[0].contains("id"));
  hub.set_level(two, StatusLevel::kNone);
  hub.status(two, "error", "muted too", "");
  CHECK(drain(hub, two).empty());
  CHECK_THROWS_AS(hub.status(0, "loud", "x"), std::invalid_argument);
}

TEST_CASE("a connection that is not drained keeps only its newest frames within its bound") {
  RosbridgeHub hub;
  hub.declare("/scan", "sensor_msgs/LaserScan", false);
  HubConnectionOptions options;
  options.max_queued_bytes = 10'000;
  int wakeups = 0;
  options.wakeup = [&wakeups] { ++wakeups; };
  const int connection = hub.open_connection(options);
  hub.subscribe(connection, "/scan", {});
  const std::string ranges(1000, 'r');
  for (int n = 0; n < 1000; ++n) hub.publish("/scan", {{"n", n}, {"ranges", ranges}});
  CHECK(wakeups == 1);  // only when the queue went from empty to not
  const RosbridgeHubStats stats = hub.stats();
  CHECK(stats.peak_queued_bytes <= 10'000);
  CHECK(stats.dropped_frames > 990);
  CHECK(hub.dropped(connection) == stats.dropped_frames);  // one connection: all its drops
  CHECK(hub.dropped(connection + 1) == 0);                  // unknown
  const auto frames = drain(hub, connection);
  CHECK(frames.back()["msg"]["n"] == 999);  // the newest survive
  CHECK(frames.size() + stats.dropped_frames == 1000);
}

TEST_CASE("incoming messages wait in order for the simulation, bounded") {
  RosbridgeHub hub;
  for (int n = 0; n < static_cast<int>(RosbridgeHub::kMaxIncoming) + 5; ++n) {
    hub.push_incoming(IncomingMessage{"/cmd_vel", "geometry_msgs/msg/Twist", counter(n), 1}, 100);
  }
  const auto taken = hub.take_incoming();
  REQUIRE(taken.size() == RosbridgeHub::kMaxIncoming);
  CHECK(taken.front().msg == counter(5));
  CHECK(hub.stats().dropped_incoming == 5);
  CHECK(hub.take_incoming().empty());

  // By bytes too: five 1 MiB frames keep only the newest four.
  for (int n = 0; n < 5; ++n) hub.push_incoming(IncomingMessage{"/cmd_vel", "", counter(n), 1}, 1 << 20);
  const auto big = hub.take_incoming();
  REQUIRE(big.size() == 4);
  CHECK(big.front().msg == counter(1));
}

TEST_CASE("the hub keeps the latest well-formed /clock and each type's definition for rosapi") {
  RosbridgeHub hub;
  hub.declare("/clock", "rosgraph_msgs/msg/Clock", false);
  CHECK(hub.wanted("/clock"));  // kept for get_time even with no subscriber
  CHECK(hub.last_clock().sec == 0);
  CHECK(hub.last_clock().nanosec == 0);
  hub.publish("/clock", {{"clock", {{"sec", 12}, {"nanosec", 500000000}}}});
  CHECK(hub.last_clock().sec == 12);
  CHECK(hub.last_clock().nanosec == 500000000u);
  // Out of builtin_interfaces/Time's range, or malformed: ignored, the last good time stays.
  hub.publish("/clock", {{"clock", {{"sec", 13}, {"nanosec", 1000000000}}}});
  hub.publish("/clock", {{"clock", {{"sec", 4294967296LL}, {"nanosec", 0}}}});
  hub.publish("/clock", {{"clock", {{"sec", "14"}, {"nanosec", 0}}}});
  hub.publish("/clock", {{"data", 1}});
  CHECK(hub.last_clock().sec == 12);

  CHECK(hub.definition("std_msgs/String").empty());
  hub.set_definition("std_msgs/String", "string data\n");
  CHECK(hub.definition("std_msgs/msg/String") == "string data\n");
  CHECK_THROWS_AS(hub.set_definition("nonsense", "x"), std::invalid_argument);
}

TEST_CASE("a status text is cut to the hub's bound, never inside a UTF-8 character") {
  RosbridgeHub hub;
  const int connection = hub.open_connection({});
  // What nlohmann writes for a malformed frame of control bytes: 8 characters per byte it quotes.
  std::string long_text = "malformed JSON: last read: '";
  for (int i = 0; i < 300; ++i) long_text += "<U+000D>";
  hub.send_status(connection, StatusLevel::kError, long_text, "x");
  // Two-byte characters from an odd offset, so that the cut falls inside one.
  std::string accents = "a";
  for (int i = 0; i < 400; ++i) accents += "\xc3\xa9";  // U+00E9
  hub.send_status(connection, StatusLevel::kError, accents, "y");
  hub.send_status(connection, StatusLevel::kError, "short", "z");
  const auto frames = drain(hub, connection);
  REQUIRE(frames.size() == 3);
  const std::string cut = frames[0]["msg"];
  CHECK(cut.size() == RosbridgeHub::kMaxStatusBytes);
  CHECK(cut.substr(cut.size() - 3) == "...");
  CHECK(cut.rfind("malformed JSON", 0) == 0);
  const std::string cut_accents = frames[1]["msg"];
  CHECK(cut_accents.size() <= RosbridgeHub::kMaxStatusBytes);
  CHECK(cut_accents.find("\xef\xbf\xbd") == std::string::npos);  // no U+FFFD: no character was split
  CHECK(cut_accents.substr(cut_accents.size() - 5) == "\xc3\xa9...");
  CHECK(frames[2]["msg"] == "short");
}

TEST_CASE("subscription ids are capped per topic, and the same id again only replaces its options") {
  RosbridgeHub hub;
  declare_capped_topics(hub);
  const int connection = hub.open_connection({});
  // 32 ids on one topic; the 33rd is refused, the same id again only replaces its options.
  for (int n = 0; n < 32; ++n) CHECK(hub.subscribe(connection, "/t0", capped_id(n)).empty());
  CHECK(hub.subscribe(connection, "/t0", capped_id(32)).find("32 subscriptions to this topic") != std::string::npos);
  CHECK(hub.subscribe(connection, "/t0", SubscribeOptions{"id5", 100, 3}).empty());
}

TEST_CASE("subscription ids are capped per connection, and unsubscribing frees room") {
  RosbridgeHub hub;
  declare_capped_topics(hub);
  const int connection = hub.open_connection({});
  // 256 on the connection: 8 topics of 32, then even a first one on a ninth topic is refused.
  for (int t = 0; t < 8; ++t) {
    for (int n = 0; n < 32; ++n) CHECK(hub.subscribe(connection, "/t" + std::to_string(t), capped_id(n)).empty());
  }
  CHECK(hub.subscribe(connection, "/t8", capped_id(0)).find("256 subscriptions on this connection") !=
        std::string::npos);

  // Unsubscribing frees room: one id, or a whole topic.
  CHECK(hub.unsubscribe(connection, "/t1", "id0"));
  CHECK(hub.subscribe(connection, "/t8", capped_id(0)).empty());
  CHECK_FALSE(hub.subscribe(connection, "/t8", capped_id(1)).empty());
  CHECK(hub.unsubscribe(connection, "/t2", ""));
  for (int n = 1; n < 32; ++n) CHECK(hub.subscribe(connection, "/t8", capped_id(n)).empty());
  // The 33rd on /t8 meets the topic's cap now, not the connection's.
  CHECK(hub.subscribe(connection, "/t8", capped_id(32)).find("32 subscriptions to this topic") != std::string::npos);
  hub.publish("/t8", counter(1));
  CHECK(drain(hub, connection).size() == 1);  // one merged subscription, one frame
}

TEST_CASE("a refused subscription changes nothing") {
  RosbridgeHub hub;
  declare_capped_topics(hub);
  const int connection = hub.open_connection({});
  // Refused by the topic's cap: the id was never added.
  for (int n = 0; n < 32; ++n) REQUIRE(hub.subscribe(connection, "/t0", capped_id(n)).empty());
  REQUIRE_FALSE(hub.subscribe(connection, "/t0", capped_id(32)).empty());
  CHECK_FALSE(hub.unsubscribe(connection, "/t0", "id32"));  // never added
  // Refused by the connection's cap: the topic is not wanted, and a publish to it reaches nobody.
  for (int t = 1; t < 8; ++t) {
    for (int n = 0; n < 32; ++n) REQUIRE(hub.subscribe(connection, "/t" + std::to_string(t), capped_id(n)).empty());
  }
  REQUIRE_FALSE(hub.subscribe(connection, "/t8", capped_id(0)).empty());
  CHECK_FALSE(hub.wanted("/t8"));
  hub.publish("/t8", counter(1));
  CHECK(drain(hub, connection).empty());
}

TEST_CASE("statuses for a dial-out link go to its local_status, never on the wire") {
  RosbridgeHub hub;
  std::vector<std::string> logged;
  HubConnectionOptions dial_out;
  dial_out.mirror_declared = true;
  dial_out.local_status = [&logged](const std::string& text) { logged.push_back(text); };
  const int link = hub.open_connection(dial_out);
  const int server_side = hub.open_connection({});
  hub.status(0, "warning", "to all");
  hub.status(link, "error", "to the link", "op7");
  hub.send_status(link, StatusLevel::kInfo, "muted by the default level", nullptr);
  CHECK(drain(hub, link).empty());
  CHECK(logged == std::vector<std::string>{"warning: to all", "error: to the link"});
  CHECK(drain(hub, server_side).size() == 1);
  CHECK_FALSE(hub.status_frame(link, StatusLevel::kError, "x", nullptr));
  CHECK(nlohmann::json::parse(*hub.status_frame(server_side, StatusLevel::kError, "x", 3)) ==
        nlohmann::json({{"op", "status"}, {"level", "error"}, {"msg", "x"}, {"id", 3}}));
  CHECK_FALSE(hub.status_frame(server_side, StatusLevel::kInfo, "muted", nullptr));

  // No sink: dropped, still not on the wire.
  HubConnectionOptions quiet;
  quiet.mirror_declared = true;
  const int silent = hub.open_connection(quiet);
  hub.status(silent, "error", "nowhere");
  CHECK(drain(hub, silent).empty());
}
