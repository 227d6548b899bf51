#pragma once
// The HTTP side of `edmhmi serve` (docs/web.md): a listener and one session per TCP connection
// that serves the built page (static files, web_static.hpp) and hands `GET /ws` upgrades to a
// WebSocket session (web_session.hpp). With a TLS context (web_tls.hpp) every connection is
// HTTPS and the socket WSS; without one, plain HTTP and WS.
//
// Hostile input: request header ≤ 8 KiB, body ≤ 16 KiB (the page never posts over HTTP), 30 s to
// send a request, GET and HEAD only, no path traversal, `nosniff` and a same-origin
// Content-Security-Policy on every file, and a WebSocket upgrade only from the same origin. Over
// HTTPS the TLS handshake has the same 30 s as a request.
//
// Thread-safety: everything runs on the server's single I/O thread.

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/context.hpp>
#include <filesystem>
#include <memory>

namespace edm::hmi {

class WebHub;

inline constexpr std::size_t kMaxHttpHeaderBytes = 8 * 1024;
inline constexpr std::size_t kMaxHttpBodyBytes = 16 * 1024;

/// Accepts connections on `endpoint` until the io_context stops: HTTPS when `tls` is set, else
/// plain HTTP. Throws boost::system::system_error when it cannot bind.
class WebListener : public std::enable_shared_from_this<WebListener> {
 public:
  WebListener(boost::asio::io_context& ioc, const boost::asio::ip::tcp::endpoint& endpoint,
              std::filesystem::path web_root, WebHub& hub,
              std::shared_ptr<boost::asio::ssl::context> tls = nullptr);
  void run();
  [[nodiscard]] boost::asio::ip::tcp::endpoint local_endpoint() const;

 private:
  void do_accept();

  boost::asio::io_context& ioc_;
  boost::asio::ip::tcp::acceptor acceptor_;
  std::filesystem::path web_root_;
  WebHub& hub_;
  std::shared_ptr<boost::asio::ssl::context> tls_;  // null: plain HTTP
};

}  // namespace edm::hmi
