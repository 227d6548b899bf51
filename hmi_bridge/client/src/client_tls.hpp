#pragma once
// How the client library verifies a bridge server over TLS (docs/security.md): a CA file (the
// chain and the host name or IP address dialled) or the SHA-256 pin of the certificate.
// Not RT-safe; pure functions over OpenSSL objects the caller owns (thread-compatible).

#include <boost/asio/ssl.hpp>
#include <memory>
#include <string>

#include "edm/bridge/client.hpp"

namespace edm::bridge {

/// A TLS 1.2+ client context that verifies against tls.ca_file, or verifies nothing when only
/// a fingerprint is given (checked after the handshake). Throws ClientError (`where` prefixes
/// the message) when neither is given or the CA file cannot be used.
std::shared_ptr<boost::asio::ssl::context> make_client_tls_context(const ClientTls& tls,
                                                                   const std::string& where);
/// The certificate must name `host` (a DNS name, or an IP address in its subjectAltName).
void expect_host_name(SSL* ssl, const std::string& host, const std::string& where);
/// SHA-256 of the peer's certificate (DER), as lower-case hex without separators; "" if none.
std::string peer_fingerprint(SSL* ssl);

}  // namespace edm::bridge
