// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: parse_ws_url, which checks --rosbridge-connect's URL (simulator/ros/bridge/ws_url.*).
// Invariants: only std::invalid_argument escapes, and its message names the URL; an accepted URL has a host
// of host characters (an IPv6 address's hex, ':' and '.'), a port in 1..65535, a resource that starts with
// '/' and holds no space, control character or '#'; and the URL written back from its parts parses to the
// same parts.
#include <stdexcept>
#include <string>

#include "fuzz_check.hpp"
#include "ros/bridge/ws_url.hpp"

using rfbsim::fuzz::check;
using rfbsim::ros::parse_ws_url;
using rfbsim::ros::WsUrl;

namespace {

bool visible(char c) { return static_cast<unsigned char>(c) > 0x20 && c != 0x7f; }

// The URL `url`'s parts spell, with the port always written and an IPv6 host in brackets.
std::string rebuilt(const WsUrl& url) {
  const bool ipv6 = url.host.find(':') != std::string::npos;
  return std::string(url.tls ? "wss://" : "ws://") + (ipv6 ? "[" + url.host + "]" : url.host) + ":" +
         std::to_string(url.port) + url.resource;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = rfbsim::fuzz::as_text(data, size);
  WsUrl url;
  try {
    url = parse_ws_url(text);
  } catch (const std::invalid_argument& refused) {
    const std::string why = refused.what();
    check(why.rfind("bad WebSocket URL '", 0) == 0, "refusal does not name the URL");
    return 0;
  }

  check(!url.host.empty(), "accepted a URL without a host");
  for (const char c : url.host) check(visible(c) && c != '/' && c != '@' && c != '[', "bad character in the host");
  check(url.port >= 1 && url.port <= 65535, "port out of range");
  check(!url.resource.empty() && url.resource.front() == '/', "resource does not start with '/'");
  for (const char c : url.resource) check(visible(c) && c != '#', "bad character in the resource");
  check(url.tls == (text.substr(0, 6) == "wss://"), "tls disagrees with the scheme");

  const std::string again_text = rebuilt(url);
  WsUrl again;
  try {
    again = parse_ws_url(again_text);
  } catch (const std::invalid_argument&) {
    check(false, "the URL written back from its parts is refused");
  }
  check(again.tls == url.tls && again.host == url.host && again.port == url.port && again.resource == url.resource,
        "the URL written back parses to other parts");
  return 0;
}
