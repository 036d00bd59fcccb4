// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: signed links. The input is a query string (a link's parameters).
// Invariants: a query that parses and has no sig signs into one that validates; changing one digit of the
// signature, or the secret, makes it fail; the canonical text ignores parameter order; sign_query refuses
// (std::invalid_argument) exactly the queries that do not parse or already hold a sig.
#include <algorithm>
#include <stdexcept>
#include <string>

#include "fuzz_check.hpp"
#include "admission/link_signature.hpp"
#include "http/query.hpp"

using rfbsim::fuzz::check;
using namespace rfbsim::manager;

namespace {

constexpr std::string_view kSecret = "fuzz-secret-0123456789";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view query = rfbsim::fuzz::as_text(data, size);
  std::string error;
  const auto params = parse_query(query, error);
  const bool has_sig =
      params && std::any_of(params->begin(), params->end(), [](const auto& p) { return p.first == "sig"; });

  std::string signed_query;
  try {
    signed_query = sign_query(query, kSecret);
  } catch (const std::invalid_argument&) {
    check(!params || has_sig, "sign_query refused a good query");
    // A link that already carries a sig is checked as the manager checks links: it must not crash.
    if (params) (void)link_signature_valid(*params, kSecret);
    return 0;
  }
  check(params && !has_sig, "sign_query accepted a query that does not parse or has a sig");

  std::string error_again;
  auto signed_params = parse_query(signed_query, error_again);
  check(signed_params.has_value(), "a signed query does not parse");
  check(link_signature_valid(*signed_params, kSecret), "a signed query does not validate");
  check(!link_signature_valid(*signed_params, "another secret"), "validates under another secret");
  check(!link_signature_valid(*params, kSecret), "validates without a sig");

  // The same parameters in reverse order carry the same signature.
  QueryParams reversed(signed_params->rbegin(), signed_params->rend());
  check(canonical_link_text(reversed) == canonical_link_text(*signed_params), "canonical text depends on order");
  check(link_signature_valid(reversed, kSecret), "reordered link does not validate");

  // One hex digit of the signature changed: refused.
  auto& sig = signed_params->back().second;
  check(signed_params->back().first == "sig" && sig.size() == 64, "sig not last or not 64 hex digits");
  sig[static_cast<std::size_t>(size) % 64] = sig[static_cast<std::size_t>(size) % 64] == '0' ? '1' : '0';
  check(!link_signature_valid(*signed_params, kSecret), "a tampered signature validates");
  return 0;
}
