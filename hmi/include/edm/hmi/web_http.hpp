#pragma once
// The HTTP side of `edmhmi serve` (docs/web.md): a listener and one session per TCP connection
// that serves the built page (static files, web_static.hpp) and hands `GET /ws` upgrades to a
// WebSocket session (web_session.hpp). With a TLS context (web_tls.hpp) every connection is
// HTTPS and the socket WSS; without one, plain HTTP and WS.
//
// Hostile input (docs/security.md "The browser HMI"): a Host on the allow-list for every request
// (web_hosts.hpp; else 421 and nothing of the page), and for the upgrade an Origin on it too
// (else 403; none at all: 403); request header ≤ 8 KiB, body ≤ 16 KiB (the page never posts
// over HTTP), 30 s to send a request, GET and HEAD only, no path traversal, `nosniff` and a
// same-origin Content-Security-Policy on every file; at most kMaxWebConnections connections
// (kMaxWebConnectionsPerAddress from one address) and kMaxWebSockets WebSockets (web_limits.hpp).
// Over HTTPS the TLS handshake has the same 30 s as a request. When accept fails (out of
// descriptors: EMFILE, ENFILE) it backs off from 10 ms to 1 s, logging once per episode.
//
// Thread-safety: everything runs on the server's single I/O thread.

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl/context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <filesystem>
#include <memory>

#include "edm/hmi/web_backoff.hpp"
#include "edm/hmi/web_hosts.hpp"
#include "edm/hmi/web_limits.hpp"

namespace edm::hmi {

class WebHub;

inline constexpr std::size_t kMaxHttpHeaderBytes = 8 * 1024;
inline constexpr std::size_t kMaxHttpBodyBytes = 16 * 1024;

/// Accepts connections on `endpoint` until the io_context stops: HTTPS when `tls` is set, else
/// plain HTTP. Throws boost::system::system_error when it cannot bind.
class WebListener : public std::enable_shared_from_this<WebListener> {
 public:
  WebListener(boost::asio::io_context& ioc, const boost::asio::ip::tcp::endpoint& endpoint,
              std::filesystem::path web_root, WebHub& hub, HostAllowList hosts,
              std::shared_ptr<boost::asio::ssl::context> tls = nullptr);
  void run();
  [[nodiscard]] boost::asio::ip::tcp::endpoint local_endpoint() const;
  /// Failed accepts so far (each episode of them is logged once).
  [[nodiscard]] std::uint64_t accept_errors() const noexcept { return accept_errors_; }

  /// What every connection shares (read-only but for the counters).
  struct Shared {
    std::filesystem::path web_root;
    WebHub& hub;
    HostAllowList hosts;
    std::shared_ptr<ConnectionCounter> connections, sockets;
  };

 private:
  void do_accept();
  void on_accept_error(const boost::system::error_code& ec);

  boost::asio::io_context& ioc_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer accept_timer_;
  Backoff accept_backoff_{std::chrono::milliseconds(10), std::chrono::milliseconds(1000)};
  std::uint64_t accept_errors_{0};
  std::shared_ptr<Shared> shared_;
  std::shared_ptr<boost::asio::ssl::context> tls_;  // null: plain HTTP
};

}  // namespace edm::hmi
