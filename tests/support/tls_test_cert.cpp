// SPDX-License-Identifier: GPL-2.0-or-later
// make_test_certificate over OpenSSL 3's EVP and X509 API: key, certificate, extensions, signature, PEM.
#include "tls_test_cert.hpp"

#include <fcntl.h>
#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

namespace rfbsim::test {

namespace {

template <typename T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const { Free(p); }
};
using KeyPtr = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using CertPtr = std::unique_ptr<X509, Deleter<X509, X509_free>>;
using BignumPtr = std::unique_ptr<BIGNUM, Deleter<BIGNUM, BN_free>>;
using ExtensionPtr = std::unique_ptr<X509_EXTENSION, Deleter<X509_EXTENSION, X509_EXTENSION_free>>;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// Throws with `step` and OpenSSL's most recent error, clearing its error queue.
[[noreturn]] void fail(const std::string& step) {
  const unsigned long code = ERR_get_error();
  char text[256] = "no OpenSSL error queued";
  if (code != 0) ERR_error_string_n(code, text, sizeof text);
  ERR_clear_error();
  throw std::runtime_error("make_test_certificate: " + step + ": " + text);
}

void check(int ok, const std::string& step) {
  if (ok != 1) fail(step);
}

// Adds one X.509 v3 extension written in openssl.cnf syntax (e.g. "critical,CA:TRUE").
void add_extension(X509* cert, int nid, const char* value) {
  X509V3_CTX context;
  X509V3_set_ctx_nodb(&context);
  X509V3_set_ctx(&context, cert, cert, nullptr, nullptr, 0);  // self-signed: issuer = subject
  const ExtensionPtr extension(X509V3_EXT_conf_nid(nullptr, &context, nid, value));
  if (!extension) fail(std::string("extension ") + OBJ_nid2sn(nid) + "=" + value);
  check(X509_add_ext(cert, extension.get(), -1), std::string("adding extension ") + OBJ_nid2sn(nid));
}

// Opens `path` for writing with `mode` (applied even when the file already existed).
FilePtr open_for_writing(const std::filesystem::path& path, mode_t mode) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, mode);
  if (fd < 0 || ::fchmod(fd, mode) != 0) {
    if (fd >= 0) ::close(fd);
    throw std::runtime_error("make_test_certificate: cannot write " + path.string());
  }
  FilePtr file(::fdopen(fd, "w"));
  if (!file) {
    ::close(fd);
    throw std::runtime_error("make_test_certificate: cannot write " + path.string());
  }
  return file;
}

}  // namespace

TestCertificate make_test_certificate(const std::filesystem::path& dir) {
  // EC P-256: as good as RSA 2048 for a test and generated in a millisecond instead of ~100.
  const KeyPtr key(EVP_EC_gen("P-256"));
  if (!key) fail("generating the P-256 key");

  const CertPtr cert(X509_new());
  if (!cert) fail("X509_new");
  check(X509_set_version(cert.get(), X509_VERSION_3), "setting the version");

  // A random positive 64-bit serial, so that repeated test certificates never look alike to a cache.
  unsigned char serial_bytes[8];
  check(RAND_bytes(serial_bytes, sizeof serial_bytes), "drawing the serial number");
  serial_bytes[0] &= 0x7F;
  const BignumPtr serial(BN_bin2bn(serial_bytes, sizeof serial_bytes, nullptr));
  if (!serial || BN_to_ASN1_INTEGER(serial.get(), X509_get_serialNumber(cert.get())) == nullptr) {
    fail("setting the serial number");
  }

  // Valid from a minute ago (clock skew between test processes is nil, but be safe) for one day.
  if (X509_gmtime_adj(X509_getm_notBefore(cert.get()), -60) == nullptr ||
      X509_gmtime_adj(X509_getm_notAfter(cert.get()), 24L * 60 * 60) == nullptr) {
    fail("setting the validity period");
  }
  check(X509_set_pubkey(cert.get(), key.get()), "setting the public key");

  // Subject = issuer = CN=127.0.0.1.
  X509_NAME* name = X509_get_subject_name(cert.get());
  check(X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_ASC, reinterpret_cast<const unsigned char*>("127.0.0.1"),
                                   -1, -1, 0),
        "setting the subject");
  check(X509_set_issuer_name(cert.get(), name), "setting the issuer");

  // The extensions `openssl req -x509` adds, plus the names TLS clients actually check (the SAN; the CN
  // is ignored when a SAN is present).
  add_extension(cert.get(), NID_basic_constraints, "critical,CA:TRUE");
  add_extension(cert.get(), NID_subject_key_identifier, "hash");
  add_extension(cert.get(), NID_authority_key_identifier, "keyid:always");
  add_extension(cert.get(), NID_subject_alt_name, "IP:127.0.0.1,DNS:localhost");
  add_extension(cert.get(), NID_ext_key_usage, "serverAuth");

  if (X509_sign(cert.get(), key.get(), EVP_sha256()) <= 0) fail("signing");

  // Write both files; the key only for its owner.
  TestCertificate out{dir / "cert.pem", dir / "key.pem"};
  {
    const FilePtr file = open_for_writing(out.cert_pem, 0644);
    check(PEM_write_X509(file.get(), cert.get()), "writing " + out.cert_pem.string());
  }
  {
    const FilePtr file = open_for_writing(out.key_pem, 0600);
    check(PEM_write_PrivateKey(file.get(), key.get(), nullptr, nullptr, 0, nullptr, nullptr),
          "writing " + out.key_pem.string());
  }
  return out;
}

}  // namespace rfbsim::test
