// SPDX-License-Identifier: GPL-2.0-or-later
// Signed links: with a secret configured, only links the researcher's tooling signed can start sessions.
//
// The signature is the lower-case hex HMAC-SHA256, keyed with the secret, of the canonical text of every
// parameter but `sig`: "name=value" pairs of the percent-decoded names and values, sorted by name (byte
// order), joined with '&'. E.g. uid=p01&scenario=lab -> HMAC(secret, "scenario=lab&uid=p01").
#pragma once

#include <string>
#include <string_view>

#include "http/query.hpp"

namespace rfbsim::manager {

/// The text that is signed for these parameters (sig left out).
std::string canonical_link_text(const QueryParams& params);

/// Lower-case hex HMAC-SHA256 of `text` keyed with `secret`.
std::string hmac_sha256_hex(std::string_view secret, std::string_view text);

/// Whether params carry a `sig` equal to the HMAC of the others (compared in constant time).
bool link_signature_valid(const QueryParams& params, std::string_view secret);

/// `query` with "&sig=..." appended; throws std::invalid_argument if the query does not parse.
std::string sign_query(std::string_view query, std::string_view secret);

}  // namespace rfbsim::manager
