#include "edm/hmi/web_tls.hpp"

#include <openssl/err.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include <filesystem>
#include <fstream>

namespace edm::hmi {

namespace {

/// A located message for a file that cannot be opened as a regular file ("" when it can).
std::string unreadable(const char* flag, const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status))
    return std::string(flag) + " " + path + ": no such file";
  if (!std::filesystem::is_regular_file(status)) {
    return std::string(flag) + " " + path + ": not a regular file";
  }
  if (!std::ifstream(path).good()) return std::string(flag) + " " + path + ": cannot be read";
  return {};
}

}  // namespace

std::shared_ptr<boost::asio::ssl::context> load_web_tls(const std::string& cert_file,
                                                        const std::string& key_file) {
  namespace ssl = boost::asio::ssl;
  for (const auto& [flag, path] : {std::pair{"--tls-cert", &cert_file}, {"--tls-key", &key_file}}) {
    if (const std::string why = unreadable(flag, *path); !why.empty()) throw WebTlsError(why);
  }
  auto ctx = std::make_shared<ssl::context>(ssl::context::tls_server);
  ctx->set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 |
                   ssl::context::no_sslv3 | ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1 |
                   ssl::context::single_dh_use);
  // An encrypted key fails here instead of OpenSSL prompting for a passphrase on the terminal.
  ctx->set_password_callback([](std::size_t, ssl::context::password_purpose) { return ""; });
  boost::system::error_code ec;
  ctx->use_certificate_chain_file(cert_file, ec);
  if (ec) {
    throw WebTlsError("--tls-cert " + cert_file + ": not a PEM certificate (" + ec.message() + ")");
  }
  ctx->use_private_key_file(key_file, ssl::context::pem, ec);
  const bool mismatch =
      ec && ERR_GET_REASON(static_cast<unsigned long>(ec.value())) == X509_R_KEY_VALUES_MISMATCH;
  if (ec && !mismatch) {
    throw WebTlsError("--tls-key " + key_file + ": not a PEM private key without a passphrase (" +
                      ec.message() + ")");
  }
  if (mismatch || SSL_CTX_check_private_key(ctx->native_handle()) != 1) {
    throw WebTlsError("--tls-key " + key_file + ": does not belong to the certificate in " +
                      cert_file);
  }
  return ctx;
}

}  // namespace edm::hmi
