// TLS transport of a bridge session (Boost.Asio SSL over OpenSSL), and the server's context.
#include <unistd.h>

#include <boost/asio/ssl.hpp>
#include <boost/asio/write.hpp>
#include <cerrno>
#include <cstring>

#include "edm/bridge/auth.hpp"
#include "edm/bridge/transport.hpp"

namespace edm::bridge {

namespace asio = boost::asio;
namespace ssl = asio::ssl;
using tcp = asio::ip::tcp;

namespace {

// The first byte of every TLS connection: a handshake record.
constexpr unsigned char kTlsHandshakeRecord = 0x16;
constexpr std::string_view kPlaintextRefusal =
    R"({"ok":false,"error":{"code":"unauthorized","message":"this port speaks TLS"}})"
    "\n";

class TlsTransport final : public Transport {
 public:
  TlsTransport(tcp::socket s, ssl::context& ctx) : stream_(std::move(s), ctx) {
    boost::system::error_code ec;
    const auto ep = stream_.lowest_layer().remote_endpoint(ec);
    if (!ec) {
      address_ = ep.address().to_string();
      peer_ = address_ + ":" + std::to_string(ep.port());
    }
    stream_.lowest_layer().set_option(tcp::no_delay(true), ec);
  }

  void async_handshake(Handler h) override {
    // Peek at the first byte: a client speaking plain JSON gets a readable refusal instead of a
    // TLS alert it cannot decode.
    auto& sock = stream_.lowest_layer();
    sock.async_wait(
        tcp::socket::wait_read, [this, h = std::move(h)](boost::system::error_code ec) mutable {
          if (ec) {
            h(ec);
            return;
          }
          unsigned char first = 0;
          const std::size_t n =
              stream_.next_layer().receive(asio::buffer(&first, 1), tcp::socket::message_peek, ec);
          if (ec || n == 0) {
            h(ec ? ec : asio::error::eof);
            return;
          }
          if (first != kTlsHandshakeRecord) {
            asio::async_write(stream_.next_layer(), asio::buffer(kPlaintextRefusal),
                              [h = std::move(h)](boost::system::error_code, std::size_t) {
                                h(ssl::error::make_error_code(ssl::error::stream_truncated));
                              });
            return;
          }
          stream_.async_handshake(ssl::stream_base::server, std::move(h));
        });
  }
  void async_read_some(asio::mutable_buffer buf, IoHandler h) override {
    stream_.async_read_some(buf, std::move(h));
  }
  void async_write(asio::const_buffer buf, IoHandler h) override {
    asio::async_write(stream_, buf, std::move(h));
  }
  void async_shutdown(Handler h) override { stream_.async_shutdown(std::move(h)); }
  void cancel() override {
    boost::system::error_code ec;
    stream_.lowest_layer().cancel(ec);
  }
  void close() override {
    boost::system::error_code ec;
    stream_.lowest_layer().shutdown(tcp::socket::shutdown_both, ec);
    stream_.lowest_layer().close(ec);
  }
  [[nodiscard]] std::string peer_address() const override { return address_; }
  [[nodiscard]] std::string peer() const override { return peer_; }
  [[nodiscard]] bool encrypted() const override { return true; }

 private:
  ssl::stream<tcp::socket> stream_;
  std::string address_;
  std::string peer_;
};

}  // namespace

std::unique_ptr<Transport> make_tls_transport(tcp::socket socket, ssl::context& ctx) {
  return std::make_unique<TlsTransport>(std::move(socket), ctx);
}

std::shared_ptr<ssl::context> make_tls_server_context(const std::string& cert_file,
                                                      const std::string& key_file) {
  for (const auto& [file, key] : {std::pair{&cert_file, "cert"}, std::pair{&key_file, "key"}}) {
    if (::access(file->c_str(), R_OK) != 0) {
      throw BridgeError(std::string("bridge.tls.") + key + " " + *file + ": " +
                        std::strerror(errno));
    }
  }
  auto ctx = std::make_shared<ssl::context>(ssl::context::tls_server);
  ctx->set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 |
                   ssl::context::no_sslv3 | ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1 |
                   ssl::context::single_dh_use);
  boost::system::error_code ec;
  ctx->use_certificate_chain_file(cert_file, ec);
  if (ec) {
    throw BridgeError("bridge.tls.cert " + cert_file + ": " + ec.message());
  }
  ctx->use_private_key_file(key_file, ssl::context::pem, ec);
  if (ec) {
    throw BridgeError("bridge.tls.key " + key_file + ": " + ec.message());
  }
  if (SSL_CTX_check_private_key(ctx->native_handle()) != 1) {
    throw BridgeError("bridge.tls.key " + key_file + ": does not match the certificate " +
                      cert_file);
  }
  return ctx;
}

}  // namespace edm::bridge
