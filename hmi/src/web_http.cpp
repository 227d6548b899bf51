#include "edm/hmi/web_http.hpp"

#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket/rfc6455.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <optional>
#include <type_traits>

#include "edm/hmi/web_session.hpp"
#include "edm/hmi/web_static.hpp"

namespace edm::hmi {

namespace beast = boost::beast;
namespace http = beast::http;
namespace asio = boost::asio;
using tcp = asio::ip::tcp;

namespace {

constexpr auto kRequestTimeout = std::chrono::seconds(30);
constexpr const char* kCsp =
    "default-src 'self'; img-src 'self' data:; style-src 'self' 'unsafe-inline'; "
    "connect-src 'self'; frame-ancestors 'none'";

void fail(beast::error_code ec, const char* what) {
  if (ec == asio::error::operation_aborted || ec == beast::error::timeout ||
      ec == http::error::end_of_stream || ec == asio::error::eof ||
      ec == asio::error::connection_reset || ec == asio::error::broken_pipe ||  // peers leaving:
      ec == asio::error::not_connected ||          // never a log line any client can ask for
      ec == asio::ssl::error::stream_truncated) {  // a browser closing TLS without close_notify
    return;
  }
  // At most 10 lines a second (the I/O thread's): failing handshakes cannot flood the log.
  static auto window = std::chrono::steady_clock::now();
  static int lines = 0;
  static unsigned long long suppressed = 0;
  const auto now = std::chrono::steady_clock::now();
  if (now - window >= std::chrono::seconds(1)) {
    if (suppressed > 0) {
      std::fprintf(stderr, "edmhmi serve: %llu more connection errors not logged\n", suppressed);
    }
    window = now;
    lines = 0;
    suppressed = 0;
  }
  if (++lines > 10) {
    ++suppressed;
    return;
  }
  std::fprintf(stderr, "edmhmi serve: %s: %s\n", what, ec.message().c_str());
}

using TlsStream = beast::ssl_stream<beast::tcp_stream>;

/// One connection: plain HTTP (`beast::tcp_stream`) or HTTPS (`TlsStream`, handshake first).
template <class Stream>
class HttpSession : public std::enable_shared_from_this<HttpSession<Stream>> {
  static constexpr bool kTls = std::is_same_v<Stream, TlsStream>;

 public:
  HttpSession(tcp::socket socket, std::shared_ptr<WebListener::Shared> shared,
              asio::ssl::context* tls, std::string peer, ConnectionCounter::Slot slot)
      : local_(local_address(socket)),
        stream_(make_stream(std::move(socket), tls)),
        shared_(std::move(shared)),
        peer_(std::move(peer)),
        slot_(std::move(slot)) {}

  void run() {
    asio::dispatch(stream_.get_executor(), [self = this->shared_from_this()] {
      if constexpr (kTls) {
        // The handshake has the same deadline as a request: a silent peer holds nothing.
        beast::get_lowest_layer(self->stream_).expires_after(kRequestTimeout);
        self->stream_.async_handshake(asio::ssl::stream_base::server, [self](beast::error_code ec) {
          if (ec) return fail(ec, "tls handshake");
          self->do_read();
        });
      } else {
        self->do_read();
      }
    });
  }

 private:
  static asio::ip::address local_address(const tcp::socket& socket) {
    beast::error_code ec;
    const auto ep = socket.local_endpoint(ec);
    return ec ? asio::ip::address() : ep.address();
  }

  static Stream make_stream(tcp::socket socket, asio::ssl::context* tls) {
    if constexpr (kTls) {
      return Stream(std::move(socket), *tls);
    } else {
      return Stream(std::move(socket));
    }
  }

  void do_read() {
    parser_.emplace();
    parser_->header_limit(kMaxHttpHeaderBytes);
    parser_->body_limit(kMaxHttpBodyBytes);
    beast::get_lowest_layer(stream_).expires_after(kRequestTimeout);
    http::async_read(stream_, buffer_, *parser_,
                     beast::bind_front_handler(&HttpSession::on_read, this->shared_from_this()));
  }

  void on_read(beast::error_code ec, std::size_t) {
    if (ec == http::error::header_limit || ec == http::error::body_limit) {
      return send(simple(http::status::payload_too_large, "request too large\n"), true);
    }
    if (ec && ec != http::error::end_of_stream &&
        ec.category() == beast::error_code(http::error::bad_method).category()) {
      return send(simple(http::status::bad_request, "bad request\n"), true);  // not logged
    }
    if (ec) return fail(ec, "http read");
    http::request<http::string_body> req = parser_->release();
    // DNS rebinding: a foreign name gets nothing of the page, nor the socket.
    const auto host = req[http::field::host];
    if (req.count(http::field::host) != 1 ||
        !shared_->hosts.allows_host(std::string_view(host.data(), host.size()), local_)) {
      return send(simple(http::status::misdirected_request, "host not allowed\n"), true);
    }
    if (beast::websocket::is_upgrade(req)) {
      if (req.target() != "/ws")
        return send(simple(http::status::not_found, "no such socket\n"), true);
      const auto origin = req[http::field::origin];
      if (req.count(http::field::origin) != 1 ||
          !shared_->hosts.allows_origin(std::string_view(origin.data(), origin.size()),
                                        std::string_view(host.data(), host.size()), local_)) {
        return send(simple(http::status::forbidden, "cross-origin WebSocket refused\n"), true);
      }
      ConnectionCounter::Slot socket = shared_->sockets->acquire("");
      if (!socket) {
        return send(simple(http::status::service_unavailable, "too many sockets\n"), true);
      }
      beast::get_lowest_layer(stream_).expires_never();
      return start_web_socket(std::move(stream_), std::move(req), shared_->hub,
                              WebPeer{peer_, std::move(slot_), std::move(socket)});
    }
    handle(req);
  }

  http::response<http::string_body> simple(http::status status, std::string body) {
    http::response<http::string_body> res{status, 11};
    res.set(http::field::server, "edmhmi");
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.set(http::field::cache_control, "no-store");
    res.set("X-Content-Type-Options", "nosniff");
    res.body() = std::move(body);
    res.prepare_payload();
    return res;
  }

  void handle(const http::request<http::string_body>& req) {
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      auto res = simple(http::status::method_not_allowed, "GET or HEAD only\n");
      res.set(http::field::allow, "GET, HEAD");
      return send(std::move(res), !req.keep_alive());
    }
    const std::string target(req.target());
    const std::optional<std::filesystem::path> file =
        resolve_static_path(shared_->web_root, target);
    if (!file) return send(simple(http::status::bad_request, "bad path\n"), true);
    std::error_code fec;
    const auto size = std::filesystem::file_size(*file, fec);
    if (fec || !std::filesystem::is_regular_file(*file, fec)) {
      return send(simple(http::status::not_found, "not found\n"), !req.keep_alive());
    }
    if (size > kMaxStaticFileBytes) {
      return send(simple(http::status::internal_server_error, "file too large\n"), true);
    }
    http::response<http::string_body> res{http::status::ok, req.version()};
    res.set(http::field::server, "edmhmi");
    res.set(http::field::content_type, std::string(content_type_for(*file)));
    res.set(http::field::cache_control, std::string(cache_control_for(target)));
    res.set("X-Content-Type-Options", "nosniff");
    res.set("Content-Security-Policy", kCsp);
    res.set("Referrer-Policy", "no-referrer");
    if (req.method() == http::verb::get) {
      std::ifstream in(*file, std::ios::binary);
      res.body().assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      res.prepare_payload();
    } else {
      res.content_length(size);
    }
    res.keep_alive(req.keep_alive());
    send(std::move(res), !req.keep_alive());
  }

  void send(http::response<http::string_body> res, bool close) {
    res_ = std::make_shared<http::response<http::string_body>>(std::move(res));
    if (close) res_->keep_alive(false);
    beast::get_lowest_layer(stream_).expires_after(kRequestTimeout);
    http::async_write(stream_, *res_,
                      [self = this->shared_from_this(), close](beast::error_code ec, std::size_t) {
                        self->on_write(ec, close);
                      });
  }

  void on_write(beast::error_code ec, bool close) {
    if (ec) return fail(ec, "http write");
    if (close) {
      if constexpr (kTls) {
        beast::get_lowest_layer(stream_).expires_after(kRequestTimeout);
        stream_.async_shutdown([self = this->shared_from_this()](beast::error_code) {});
      } else {
        stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
      }
      return;
    }
    res_.reset();
    do_read();
  }

  asio::ip::address local_;  // the address the client dialled (web_hosts.hpp)
  Stream stream_;
  beast::flat_buffer buffer_{kMaxHttpHeaderBytes + kMaxHttpBodyBytes};
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<http::response<http::string_body>> res_;
  std::shared_ptr<WebListener::Shared> shared_;
  std::string peer_;
  ConnectionCounter::Slot slot_;
};

}  // namespace

WebListener::WebListener(asio::io_context& ioc, const tcp::endpoint& endpoint,
                         std::filesystem::path web_root, WebHub& hub, HostAllowList hosts,
                         std::shared_ptr<asio::ssl::context> tls)
    : ioc_(ioc),
      acceptor_(ioc),
      accept_timer_(ioc),
      shared_(std::make_shared<Shared>(Shared{
          std::move(web_root), hub, std::move(hosts),
          std::make_shared<ConnectionCounter>(kMaxWebConnections, kMaxWebConnectionsPerAddress),
          std::make_shared<ConnectionCounter>(kMaxWebSockets, kMaxWebSockets)})),
      tls_(std::move(tls)) {
  acceptor_.open(endpoint.protocol());
  acceptor_.set_option(asio::socket_base::reuse_address(true));
  acceptor_.bind(endpoint);
  acceptor_.listen(asio::socket_base::max_listen_connections);
}

void WebListener::run() { do_accept(); }

tcp::endpoint WebListener::local_endpoint() const { return acceptor_.local_endpoint(); }

void WebListener::do_accept() {
  acceptor_.async_accept(asio::make_strand(ioc_), [self = shared_from_this()](beast::error_code ec,
                                                                              tcp::socket socket) {
    if (ec) return self->on_accept_error(ec);
    if (const auto n = self->accept_backoff_.succeed(); n > 0) {
      std::fprintf(stderr, "edmhmi serve: accepting again after %llu failed accepts\n",
                   static_cast<unsigned long long>(n));
    }
    beast::error_code pec;
    const auto remote = socket.remote_endpoint(pec);
    std::string peer = pec ? std::string("?") : remote.address().to_string();
    // Over the caps: the connection is dropped before anything is read from it.
    if (ConnectionCounter::Slot slot = self->shared_->connections->acquire(peer)) {
      if (self->tls_) {
        std::make_shared<HttpSession<TlsStream>>(std::move(socket), self->shared_, self->tls_.get(),
                                                 std::move(peer), std::move(slot))
            ->run();
      } else {
        std::make_shared<HttpSession<beast::tcp_stream>>(std::move(socket), self->shared_, nullptr,
                                                         std::move(peer), std::move(slot))
            ->run();
      }
    }
    if (self->acceptor_.is_open()) self->do_accept();
  });
}

// Out of descriptors (EMFILE/ENFILE), out of memory, or a network error: accept again later,
// backing off to 1 s, and log once per episode rather than once per failure (issue 31: it spun
// at 70-85 % CPU writing "Too many open files" without end).
void WebListener::on_accept_error(const boost::system::error_code& ec) {
  if (ec == asio::error::operation_aborted || !acceptor_.is_open()) return;
  ++accept_errors_;
  bool first = false;
  const auto delay = accept_backoff_.fail(&first);
  if (first) std::fprintf(stderr, "edmhmi serve: accept: %s; backing off\n", ec.message().c_str());
  accept_timer_.expires_after(delay);
  accept_timer_.async_wait([self = shared_from_this()](boost::system::error_code e) {
    if (!e) self->do_accept();
  });
}

}  // namespace edm::hmi
