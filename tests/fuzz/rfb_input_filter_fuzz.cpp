// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: the watch relay's RFB input filter, on a client-to-server byte stream.
// Invariants: how the stream is split into chunks changes nothing (output, failure, drop count); what
// the filter passes holds no input message: a second filter passes it unchanged, drops nothing and does
// not fail; a failure reason fits a WebSocket close frame.
#include <string>

#include "fuzz_check.hpp"
#include "http/rfb_input_filter.hpp"

using rfbsim::fuzz::check;
using rfbsim::manager::RfbInputFilter;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view stream = rfbsim::fuzz::as_text(data, size);

  // The whole stream in one call.
  RfbInputFilter whole;
  const std::string passed = whole.forward(stream);
  check(whole.failure().size() <= 123, "failure reason too long for a close frame");
  check(passed.size() <= stream.size(), "filter output longer than its input");

  // The same stream in chunks of 1, 2, 3, ... 7 bytes (sizes from the data, so the fuzzer steers them).
  RfbInputFilter chunked;
  std::string chunked_out;
  for (std::size_t at = 0; at < stream.size();) {
    const std::size_t count = std::min<std::size_t>(1 + static_cast<unsigned char>(stream[at]) % 7, stream.size() - at);
    chunked_out += chunked.forward(stream.substr(at, count));
    at += count;
  }
  check(chunked_out == passed, "chunking changed the output");
  check(chunked.failed() == whole.failed() && chunked.failure() == whole.failure(), "chunking changed the failure");
  check(chunked.dropped_messages() == whole.dropped_messages(), "chunking changed the drop count");

  // What passed is clean: filtering it again changes nothing.
  RfbInputFilter again;
  const std::string passed_again = again.forward(passed);
  check(!again.failed(), "the filter's own output does not frame");
  check(again.dropped_messages() == 0, "the filter's own output holds an input message");
  check(passed_again == passed, "the filter's own output changes when filtered again");
  return 0;
}
