// Connecting: dial (with a timeout), TLS with the server verified, hello; reconnect with the
// subscriptions and the trace replayed; the auto-reconnect loop with exponential back-off;
// the Client's life cycle.
#include <boost/asio/connect.hpp>
#include <boost/asio/post.hpp>

#include "client_impl.hpp"
#include "client_tls.hpp"

namespace edm::bridge {

namespace {

/// Closes the socket on the I/O thread, so the operation waited on completes.
void close_on_io_thread(asio::io_context& ioc, const std::shared_ptr<Conn>& c) {
  asio::post(ioc, [c] {
    boost::system::error_code ignored;
    c->socket.close(ignored);
  });
}

}  // namespace

Client::Impl::Impl() {
  work.emplace(ioc.get_executor());
  io_thread = std::thread([this] { ioc.run(); });
}

/// TLS over the connected socket: the server is verified against a CA file (chain and name)
/// or a pinned SHA-256 fingerprint of its certificate. Throws ClientError.
void Client::Impl::tls_handshake(const std::shared_ptr<Conn>& c, const ClientOptions& o) {
  const std::string where = "bridge: TLS to " + o.host + ":" + std::to_string(o.port) + ": ";
  c->tls_ctx = make_client_tls_context(o.tls, where);
  c->tls.emplace(c->socket, *c->tls_ctx);
  SSL* ssl = c->tls->native_handle();
  if (!o.tls.ca_file.empty()) {
    expect_host_name(ssl, o.host, where);
  }
  std::promise<boost::system::error_code> done;
  auto f = done.get_future();
  asio::post(ioc, [c, &done] {
    c->tls->async_handshake(asio::ssl::stream_base::client,
                            [&done](boost::system::error_code e) { done.set_value(e); });
  });
  if (f.wait_for(o.timeout) != std::future_status::ready) {
    close_on_io_thread(ioc, c);
    f.wait();
    throw ClientError(where + "handshake timed out");
  }
  if (const auto e = f.get()) {
    throw ClientError(where + "handshake failed: " + e.message());
  }
  if (!o.tls.fingerprint.empty()) {
    const std::string got = peer_fingerprint(ssl);
    if (got != normalise_fingerprint(o.tls.fingerprint)) {
      close_on_io_thread(ioc, c);
      throw ClientError(where + "the server's certificate fingerprint " + got +
                        " is not the pinned one");
    }
  }
}

Role Client::Impl::connect_once() {
  ClientOptions o;
  {
    std::lock_guard lock(mu);
    o = opt;
  }
  drop_connection();
  auto c = std::make_shared<Conn>(ioc);
  boost::system::error_code ec;
  asio::io_context resolver_ctx;
  tcp::resolver resolver(resolver_ctx);
  const auto endpoints = resolver.resolve(o.host, std::to_string(o.port), ec);
  if (ec) {
    throw ClientError("bridge: cannot resolve " + o.host + ": " + ec.message());
  }
  std::promise<boost::system::error_code> connected_p;
  auto connected_f = connected_p.get_future();
  asio::post(ioc, [c, endpoints, &connected_p] {
    asio::async_connect(c->socket, endpoints,
                        [&connected_p](boost::system::error_code e, const tcp::endpoint&) {
                          connected_p.set_value(e);
                        });
  });
  if (connected_f.wait_for(o.timeout) != std::future_status::ready) {
    close_on_io_thread(ioc, c);
    connected_f.wait();
    throw ClientError("bridge: connect to " + o.host + ":" + std::to_string(o.port) + " timed out");
  }
  if (const auto e = connected_f.get()) {
    throw ClientError("bridge: connect to " + o.host + ":" + std::to_string(o.port) + ": " +
                      e.message());
  }
  if (o.tls.enabled) {
    tls_handshake(c, o);
  }
  {
    std::lock_guard lock(mu);
    conn = c;
    lost = false;
  }
  asio::post(ioc, [self = shared_from_this(), c] {
    boost::system::error_code ignored;
    c->socket.set_option(tcp::no_delay(true), ignored);
    c->last_write = std::chrono::steady_clock::now();
    self->start_read(c);
    self->arm_keepalive(c);
  });
  const Reply hello = request("hello", hello_params(o.token, o.peer), {});
  if (!hello) {
    drop_connection();
    throw ClientError(
        "bridge: hello refused: " + (hello.code ? std::string(to_string(*hello.code)) + ": " : "") +
            hello.message,
        hello.code);
  }
  const Role r = hello.body.value("role", "viewer") == "operator" ? Role::kOperator : Role::kViewer;
  ConnectionHandler h;
  {
    std::lock_guard lock(mu);
    role = r;
    h = on_conn;
  }
  connected = true;
  connections.fetch_add(1);
  if (h) {
    h(true);
  }
  return r;
}

Role Client::Impl::reconnect_and_replay() {
  const Role r = connect_once();
  std::vector<std::string> topics;
  std::vector<std::string> vars;
  int rate = 0;
  {
    std::lock_guard lock(mu);
    topics = sub_topics;
    vars = trace_vars;
    rate = sub_rate;
  }
  if (!topics.empty()) {
    request("subscribe", {{"topics", topics}, {"rate_hz", rate}}, {});
  }
  if (!vars.empty()) {
    request("trace.start", {{"vars", vars}}, {});
  }
  return r;
}

void Client::Impl::reconnect_loop() {
  std::chrono::milliseconds backoff{0};
  std::unique_lock lock(mu);
  while (!closing) {
    cv.wait(lock, [&] { return closing || lost; });
    if (closing) {
      break;
    }
    backoff = backoff.count() == 0 ? opt.reconnect_min : std::min(backoff * 2, opt.reconnect_max);
    if (cv.wait_for(lock, backoff, [&] { return closing; })) {
      break;
    }
    lock.unlock();
    try {
      reconnect_and_replay();
      backoff = std::chrono::milliseconds{0};
    } catch (const ClientError&) {
      std::lock_guard relock(mu);
      lost = !closing;  // try again
    }
    lock.lock();
  }
}

void Client::Impl::shutdown() {
  {
    std::lock_guard lock(mu);
    closing = true;
  }
  cv.notify_all();
  if (reconnect_thread.joinable()) {
    reconnect_thread.join();
  }
  drop_connection();
}

Client::Client() : impl_(std::make_shared<Impl>()) {}

Client::~Client() {
  impl_->shutdown();
  // Every socket is closed and every timer cancelled: run() returns once their handlers ran.
  impl_->work.reset();
  impl_->io_thread.join();
}

Role Client::connect(const ClientOptions& options) {
  {
    std::lock_guard lock(impl_->mu);
    impl_->opt = options;
    impl_->has_options = true;
    impl_->closing = false;
  }
  const Role r = impl_->connect_once();
  if (options.auto_reconnect && !impl_->reconnect_thread.joinable()) {
    impl_->reconnect_thread = std::thread([impl = impl_.get()] { impl->reconnect_loop(); });
  }
  return r;
}

void Client::close() { impl_->shutdown(); }

bool Client::connected() const noexcept { return impl_->connected.load(); }

Role Client::role() const noexcept {
  std::lock_guard lock(impl_->mu);
  return impl_->role;
}

void Client::set_connection_handler(ConnectionHandler h) {
  std::lock_guard lock(impl_->mu);
  impl_->on_conn = std::move(h);
}

Role Client::reconnect() { return impl_->reconnect_and_replay(); }

std::uint64_t Client::connections() const noexcept { return impl_->connections.load(); }

}  // namespace edm::bridge
