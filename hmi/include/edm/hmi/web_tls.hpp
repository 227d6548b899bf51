#pragma once
// HTTPS for `edmhmi serve` (docs/web.md "HTTPS", docs/security.md): the server's certificate and
// key, loaded once at start-up into an OpenSSL context that every HTTPS/WSS connection shares.
//
// Thread-safety: load_web_tls() runs before the server starts; the context is then only read.

#include <boost/asio/ssl/context.hpp>
#include <memory>
#include <stdexcept>
#include <string>

namespace edm::hmi {

/// A certificate or key that cannot be used; what() names the file and says why in one line.
class WebTlsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A TLS 1.2+ server context with the PEM certificate chain `cert_file` and the PEM private key
/// `key_file`. Throws WebTlsError when a file is missing, unreadable, not PEM of its kind, or when
/// the key does not belong to the certificate.
[[nodiscard]] std::shared_ptr<boost::asio::ssl::context> load_web_tls(const std::string& cert_file,
                                                                      const std::string& key_file);

}  // namespace edm::hmi
