// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: websocketpp's HTTP request parser (websocketpp::http::parser::request::consume), which
// reads every request sim_manager's port receives before any of our code sees it.
// Invariants: it fails only with websocketpp::http::exception; splitting the bytes into chunks does not
// change the outcome; a ready request has a method and a Host header, and its request line reads back the
// same from raw().
#include <websocketpp/http/request.hpp>

#include <optional>
#include <string>

#include "fuzz_check.hpp"

using rfbsim::fuzz::check;
using Request = websocketpp::http::parser::request;

namespace {

// Feeds `bytes` to `request` in chunks of `chunk` bytes, as consume's callers do; nothing on an error.
std::optional<bool> consume_all(Request& request, std::string_view bytes, std::size_t chunk) {
  try {
    for (std::size_t at = 0; at < bytes.size() && !request.ready();) {
      const std::size_t count = std::min(chunk, bytes.size() - at);
      const std::size_t used = request.consume(bytes.data() + at, count);
      check(used <= count, "consume used more bytes than it was given");
      at += count;
    }
  } catch (const websocketpp::http::exception&) {
    return std::nullopt;
  }
  return request.ready();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes = rfbsim::fuzz::as_text(data, size);
  Request whole;
  const auto whole_ready = consume_all(whole, bytes, bytes.size() + 1);
  Request chunked;
  const auto chunked_ready = consume_all(chunked, bytes, 3);
  check(whole_ready.has_value() == chunked_ready.has_value(), "chunking changed whether it fails");
  if (!whole_ready || !*whole_ready) return 0;
  check(chunked_ready && *chunked_ready, "chunking changed whether it completes");
  check(!whole.get_method().empty() && !whole.get_header("Host").empty(), "ready without method or Host");
  check(chunked.get_method() == whole.get_method() && chunked.get_uri() == whole.get_uri() &&
            chunked.get_headers() == whole.get_headers(),
        "chunking changed the request");

  // The request written out again parses to the same request line. (Not the same headers: raw() writes
  // values with stray CRs and merged repeats as they are, which do not read back alike; sim_manager never
  // writes requests out again, it only looks headers up.)
  Request reread;
  const std::string raw = whole.raw();
  const auto reread_ready = consume_all(reread, raw, raw.size() + 1);
  if (reread_ready && *reread_ready) {
    check(reread.get_method() == whole.get_method() && reread.get_uri() == whole.get_uri() &&
              reread.get_version() == whole.get_version(),
          "raw() parses back to another request line");
  }
  return 0;
}
