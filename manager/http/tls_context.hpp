// SPDX-License-Identifier: GPL-2.0-or-later
// TLS settings for the public port: TLS 1.2 and later, the certificate chain and key loaded once, at
// start-up, so that a bad file stops the manager then rather than at the first participant.
#pragma once

#include <boost/asio/ssl/context.hpp>
#include <memory>

#include "config/config.hpp"

namespace rfbsim::manager {

/// The server's TLS context from config.tls_certificate and tls_private_key. Throws std::runtime_error naming
/// the file that cannot be loaded, or saying that the key does not match the certificate.
std::shared_ptr<boost::asio::ssl::context> make_tls_context(const ManagerConfig& config);

}  // namespace rfbsim::manager
