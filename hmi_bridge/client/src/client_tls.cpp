#include "client_tls.hpp"

#include <boost/asio/ip/address.hpp>
#include <cctype>

namespace edm::bridge {

namespace asio = boost::asio;

std::shared_ptr<asio::ssl::context> make_client_tls_context(const ClientTls& tls,
                                                            const std::string& where) {
  auto ctx = std::make_shared<asio::ssl::context>(asio::ssl::context::tls_client);
  ctx->set_options(asio::ssl::context::default_workarounds | asio::ssl::context::no_sslv2 |
                   asio::ssl::context::no_sslv3 | asio::ssl::context::no_tlsv1 |
                   asio::ssl::context::no_tlsv1_1);
  boost::system::error_code ec;
  if (!tls.ca_file.empty()) {
    ctx->load_verify_file(tls.ca_file, ec);
    if (ec) {
      throw ClientError(where + "CA file " + tls.ca_file + ": " + ec.message());
    }
    ctx->set_verify_mode(asio::ssl::verify_peer);
  } else if (tls.fingerprint.empty()) {
    throw ClientError(where + "no way to verify the server: give a CA file or a fingerprint");
  } else {
    ctx->set_verify_mode(asio::ssl::verify_none);  // the pin is checked after the handshake
  }
  return ctx;
}

void expect_host_name(SSL* ssl, const std::string& host, const std::string& where) {
  boost::system::error_code not_ip;
  asio::ip::make_address(host, not_ip);
  X509_VERIFY_PARAM* param = SSL_get0_param(ssl);
  const int ok = not_ip ? X509_VERIFY_PARAM_set1_host(param, host.c_str(), 0)
                        : X509_VERIFY_PARAM_set1_ip_asc(param, host.c_str());
  if (ok != 1) {
    throw ClientError(where + "cannot set the name to verify");
  }
  if (not_ip) {
    SSL_set_tlsext_host_name(ssl, host.c_str());
  }
}

/// SHA-256 of the peer's certificate (DER), as lower-case hex without separators.
std::string peer_fingerprint(SSL* ssl) {
  X509* cert = SSL_get1_peer_certificate(ssl);
  if (cert == nullptr) {
    return "";
  }
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  const int ok = X509_digest(cert, EVP_sha256(), md, &n);
  X509_free(cert);
  if (ok != 1) {
    return "";
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < n; ++i) {
    out += kHex[md[i] >> 4];
    out += kHex[md[i] & 0xF];
  }
  return out;
}

std::string normalise_fingerprint(std::string_view text) {
  std::string out;
  for (const char ch : text) {
    if (ch == ':' || ch == ' ') {
      continue;
    }
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  }
  return out;
}

}  // namespace edm::bridge
