// SPDX-License-Identifier: GPL-2.0-or-later
#include "http/tls_context.hpp"

#include <stdexcept>

namespace rfbsim::manager {

std::shared_ptr<boost::asio::ssl::context> make_tls_context(const ManagerConfig& config) {
  namespace ssl = boost::asio::ssl;
  auto context = std::make_shared<ssl::context>(ssl::context::tls_server);
  context->set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 | ssl::context::no_sslv3 |
                       ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1 | ssl::context::single_dh_use);
  boost::system::error_code ec;
  context->use_certificate_chain_file(config.tls_certificate, ec);
  if (ec) throw std::runtime_error("cannot load the TLS certificate " + config.tls_certificate + ": " + ec.message());
  context->use_private_key_file(config.tls_private_key, ssl::context::pem, ec);
  if (ec) throw std::runtime_error("cannot load the TLS private key " + config.tls_private_key + ": " + ec.message());
  if (SSL_CTX_check_private_key(context->native_handle()) != 1) {
    throw std::runtime_error("the TLS private key " + config.tls_private_key + " does not match the certificate");
  }
  return context;
}

}  // namespace rfbsim::manager
