// SPDX-License-Identifier: GPL-2.0-or-later
// make_test_certificate: a fresh self-signed TLS certificate for loopback tests, made with OpenSSL's C API.
#pragma once

#include <filesystem>

namespace rfbsim::test {

/// Where make_test_certificate wrote its two PEM files.
struct TestCertificate {
  std::filesystem::path cert_pem;  ///< the X.509 certificate (PEM "CERTIFICATE")
  std::filesystem::path key_pem;   ///< its unencrypted private key (PEM "PRIVATE KEY", PKCS#8), mode 0600
};

/// Generates an EC P-256 key and a self-signed X.509 v3 certificate for it: CN=127.0.0.1,
/// subjectAltName IP:127.0.0.1 and DNS:localhost, valid from one minute ago for one day, usable as its
/// own trust anchor (CA:TRUE) and as a TLS server certificate. Writes `dir`/cert.pem and `dir`/key.pem,
/// replacing existing files; `dir` must exist. Throws std::runtime_error naming the failing step.
/// Thread-safe (no shared state).
TestCertificate make_test_certificate(const std::filesystem::path& dir);

}  // namespace rfbsim::test
