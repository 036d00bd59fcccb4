// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: the manager's query-string and percent-encoding functions.
// Invariants: a decoded text has no control character and survives encode-then-decode; the encoder writes
// only unreserved characters and %XX; a parsed query has distinct names and, written out again with
// percent_encode, parses to the same pairs; split_target splits at the first '?' and loses nothing.
#include <string>

#include "fuzz_check.hpp"
#include "http/query.hpp"

using rfbsim::fuzz::check;
using namespace rfbsim::manager;

namespace {

bool only_unreserved_or_escapes(const std::string& text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    const bool unreserved = (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') ||
                            ch == '-' || ch == '.' || ch == '_' || ch == '~';
    if (unreserved) continue;
    // An escape: '%' and two upper-case hex digits.
    if (ch != '%' || i + 2 >= text.size()) return false;
    for (const char digit : {text[i + 1], text[i + 2]}) {
      if (!((digit >= '0' && digit <= '9') || (digit >= 'A' && digit <= 'F'))) return false;
    }
    i += 2;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = rfbsim::fuzz::as_text(data, size);

  if (const auto decoded = percent_decode(text)) {
    for (const char ch : *decoded) {
      check(static_cast<unsigned char>(ch) >= 0x20 && ch != 0x7f, "control character decoded");
    }
    check(decoded->size() <= text.size(), "decoded text longer than its encoding");
    const std::string encoded = percent_encode(*decoded);
    check(only_unreserved_or_escapes(encoded), "encoder wrote a reserved character");
    const auto again = percent_decode(encoded);
    check(again && *again == *decoded, "encode then decode changed the text");
  }

  std::string error;
  if (const auto params = parse_query(text, error)) {
    std::string rebuilt;
    for (std::size_t i = 0; i < params->size(); ++i) {
      const auto& [name, value] = (*params)[i];
      check(!name.empty(), "empty parameter name");
      for (std::size_t j = 0; j < i; ++j) check((*params)[j].first != name, "repeated parameter accepted");
      rebuilt += (i == 0 ? "" : "&") + percent_encode(name) + "=" + percent_encode(value);
    }
    std::string error_again;
    const auto again = parse_query(rebuilt, error_again);
    check(again && *again == *params, "query does not round-trip");
  } else {
    check(!error.empty(), "refused query without a reason");
    check(error.size() < 200, "error message not bounded");
  }

  const auto [path, query] = split_target(text);
  const std::size_t mark = text.find('?');
  if (mark == std::string_view::npos) {
    check(path == text && query.empty(), "target without '?' split");
  } else {
    check(path.size() == mark && query.size() == text.size() - mark - 1, "target split elsewhere than its '?'");
  }
  return 0;
}
