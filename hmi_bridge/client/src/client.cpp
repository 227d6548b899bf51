#include "edm/bridge/client.hpp"

#include <array>
#include <boost/asio/connect.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <condition_variable>
#include <deque>
#include <future>
#include <map>
#include <mutex>
#include <thread>

#include "client_tls.hpp"

namespace edm::bridge {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

namespace {

constexpr std::size_t kChunkBytes = 512 * 1024;  // well under the server's 1 MiB line limit

Reply transport_error(std::string message) {
  Reply r;
  r.message = std::move(message);
  return r;
}

Reply to_reply(Json j) {
  Reply r;
  r.ok = j.value("ok", false);
  if (!r.ok) {
    if (auto e = j.find("error"); e != j.end() && e->is_object()) {
      ErrorCode c{};
      if (error_code_from_string(e->value("code", ""), c)) {
        r.code = c;
      }
      r.message = e->value("message", "");
      if (auto d = e->find("details"); d != e->end()) {
        r.details = *d;
      }
    }
    if (!r.code) {
      r.code = ErrorCode::kBadRequest;
      if (r.message.empty()) {
        r.message = "malformed error reply";
      }
    }
  }
  r.body = std::move(j);
  return r;
}

}  // namespace

/// One TCP connection, with TLS over it when the options ask; touched only on the I/O thread
/// once started.
struct Conn {
  explicit Conn(asio::io_context& ioc) : socket(ioc), keepalive(ioc) {}
  tcp::socket socket;
  std::shared_ptr<asio::ssl::context> tls_ctx;
  std::optional<asio::ssl::stream<tcp::socket&>> tls;
  asio::steady_timer keepalive;
  std::array<char, 64 * 1024> rx{};
  std::string line;
  bool discarding{false};
  std::deque<std::string> wq;
  bool writing{false};
  bool dead{false};
  std::chrono::steady_clock::time_point last_write{};
};

using Promise = std::promise<Reply>;

struct Client::Impl : std::enable_shared_from_this<Impl> {
  asio::io_context ioc{1};
  std::optional<asio::executor_work_guard<asio::io_context::executor_type>> work;
  std::thread io_thread;

  mutable std::mutex mu;  // guards everything below
  std::shared_ptr<Conn> conn;
  std::map<std::int64_t, std::shared_ptr<Promise>> pending;
  std::deque<std::shared_ptr<Promise>> anonymous;  // raw requests awaiting an id-less reply
  std::int64_t next_id{1};
  ClientOptions opt;
  bool has_options{false};
  Role role{Role::kViewer};
  std::vector<std::string> sub_topics;
  int sub_rate{0};
  std::vector<std::string> trace_vars;
  EventHandler on_event;
  ConnectionHandler on_conn;
  bool closing{false};
  bool lost{false};
  std::condition_variable cv;
  std::thread reconnect_thread;
  std::atomic<bool> connected{false};
  std::atomic<std::uint64_t> connections{0};

  Impl() {
    work.emplace(ioc.get_executor());
    io_thread = std::thread([this] { ioc.run(); });
  }

  [[nodiscard]] bool on_io_thread() const {
    return std::this_thread::get_id() == io_thread.get_id();
  }

  // ---- I/O thread ----
  void start_read(const std::shared_ptr<Conn>& c) {
    auto h = [self = shared_from_this(), c](boost::system::error_code ec, std::size_t n) {
      self->on_read(c, ec, n);
    };
    if (c->tls) {
      c->tls->async_read_some(asio::buffer(c->rx), std::move(h));
    } else {
      c->socket.async_read_some(asio::buffer(c->rx), std::move(h));
    }
  }

  void on_read(const std::shared_ptr<Conn>& c, boost::system::error_code ec, std::size_t n) {
    if (c->dead) {
      return;
    }
    if (ec) {
      lose(c, ec == asio::error::eof ? "connection closed by the server" : ec.message());
      return;
    }
    std::string_view chunk(c->rx.data(), n);
    while (!chunk.empty()) {
      const auto nl = chunk.find('\n');
      const std::string_view part = chunk.substr(0, nl);
      if (c->discarding) {
        c->discarding = nl == std::string_view::npos;
      } else if (c->line.size() + part.size() > opt.max_line_bytes) {
        c->line.clear();
        c->discarding = nl == std::string_view::npos;
      } else {
        c->line.append(part);
        if (nl != std::string_view::npos) {
          std::string line = std::move(c->line);
          c->line.clear();
          handle_line(line);
        }
      }
      if (nl == std::string_view::npos) {
        break;
      }
      chunk.remove_prefix(nl + 1);
    }
    start_read(c);
  }

  void handle_line(const std::string& line) {
    Json j;
    std::string why;
    if (!parse_json_strict(line, j, why) || !j.is_object()) {
      return;
    }
    if (j.contains("event")) {
      EventHandler h;
      {
        std::lock_guard lock(mu);
        h = on_event;
      }
      if (h) {
        h(j);
      }
      return;
    }
    std::shared_ptr<Promise> p;
    {
      std::lock_guard lock(mu);
      auto id = j.find("id");
      if (id != j.end() && id->is_number_integer()) {
        auto it = pending.find(id->get<std::int64_t>());
        if (it != pending.end()) {
          p = it->second;
          pending.erase(it);
        }
      } else if (id == j.end()) {
        // An id-less reply (bad_json, too_large): the server answers in order, so it belongs
        // to the oldest request still waiting.
        if (!anonymous.empty()) {
          p = anonymous.front();
          anonymous.pop_front();
        } else if (!pending.empty()) {
          p = pending.begin()->second;
          pending.erase(pending.begin());
        }
      }
    }
    if (p) {
      p->set_value(to_reply(std::move(j)));
    }
  }

  void write(const std::shared_ptr<Conn>& c, std::string line) {
    if (c->dead) {
      return;
    }
    c->wq.push_back(std::move(line));
    c->last_write = std::chrono::steady_clock::now();
    if (!c->writing) {
      do_write(c);
    }
  }

  void do_write(const std::shared_ptr<Conn>& c) {
    if (c->dead || c->wq.empty()) {
      return;
    }
    c->writing = true;
    auto h = [self = shared_from_this(), c](boost::system::error_code ec, std::size_t) {
      c->writing = false;
      if (ec) {
        self->lose(c, ec.message());
        return;
      }
      c->wq.pop_front();
      self->do_write(c);
    };
    if (c->tls) {
      asio::async_write(*c->tls, asio::buffer(c->wq.front()), std::move(h));
    } else {
      asio::async_write(c->socket, asio::buffer(c->wq.front()), std::move(h));
    }
  }

  void arm_keepalive(const std::shared_ptr<Conn>& c) {
    c->keepalive.expires_after(opt.keepalive);
    c->keepalive.async_wait([self = shared_from_this(), c](boost::system::error_code ec) {
      if (ec || c->dead) {
        return;
      }
      if (std::chrono::steady_clock::now() - c->last_write >= self->opt.keepalive / 2) {
        self->write(c, "{\"id\":\"keepalive\",\"op\":\"ping\"}\n");
      }
      self->arm_keepalive(c);
    });
  }

  /// The connection is gone: fail what waits, tell the handler, wake the reconnector.
  void lose(const std::shared_ptr<Conn>& c, const std::string& why) {
    if (c->dead) {
      return;
    }
    c->dead = true;
    boost::system::error_code ignored;
    c->socket.close(ignored);
    c->keepalive.cancel();
    std::map<std::int64_t, std::shared_ptr<Promise>> waiting;
    std::deque<std::shared_ptr<Promise>> anon;
    ConnectionHandler h;
    bool was_current = false;
    {
      std::lock_guard lock(mu);
      if (conn == c) {
        was_current = true;
        conn.reset();
        waiting.swap(pending);
        anon.swap(anonymous);
        connected = false;
        lost = !closing;
        h = on_conn;
      }
    }
    cv.notify_all();
    for (auto& [id, p] : waiting) {
      p->set_value(transport_error("disconnected: " + why));
    }
    for (auto& p : anon) {
      p->set_value(transport_error("disconnected: " + why));
    }
    if (was_current && h) {
      h(false);
    }
  }

  // ---- any thread ----
  Reply wait(const std::shared_ptr<Promise>& p, std::optional<std::chrono::milliseconds> timeout,
             std::optional<std::int64_t> id) {
    auto f = p->get_future();
    std::chrono::milliseconds t;
    {
      std::lock_guard lock(mu);
      t = timeout.value_or(opt.timeout);
    }
    if (f.wait_for(t) != std::future_status::ready) {
      std::lock_guard lock(mu);
      if (id) {
        pending.erase(*id);
      } else {
        std::erase(anonymous, p);
      }
      return transport_error("timeout after " + std::to_string(t.count()) + " ms");
    }
    return f.get();
  }

  Reply send(const std::string& line, std::optional<std::int64_t> id,
             std::optional<std::chrono::milliseconds> timeout) {
    if (on_io_thread()) {
      return transport_error("deadlock: request() from an event handler");
    }
    auto p = std::make_shared<Promise>();
    std::shared_ptr<Conn> c;
    {
      std::lock_guard lock(mu);
      c = conn;
      if (!c) {
        return transport_error("not connected");
      }
      if (id) {
        pending[*id] = p;
      } else {
        anonymous.push_back(p);
      }
    }
    asio::post(ioc, [self = shared_from_this(), c, line] { self->write(c, line); });
    return wait(p, timeout, id);
  }

  Reply request(std::string_view op, const Json& params,
                std::optional<std::chrono::milliseconds> timeout) {
    std::int64_t id = 0;
    {
      std::lock_guard lock(mu);
      id = next_id++;
    }
    return send(to_line(make_request(id, op, params)), id, timeout);
  }

  void drop_connection() {
    std::shared_ptr<Conn> c;
    {
      std::lock_guard lock(mu);
      c = conn;
    }
    if (!c) {
      return;
    }
    std::promise<void> done;
    asio::post(ioc, [self = shared_from_this(), c, &done] {
      self->lose(c, "closed by the client");
      done.set_value();
    });
    done.get_future().wait();
  }

  /// TLS over the connected socket: the server is verified against a CA file (chain and name)
  /// or a pinned SHA-256 fingerprint of its certificate. Throws ClientError.
  void tls_handshake(const std::shared_ptr<Conn>& c, const ClientOptions& o) {
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
      asio::post(ioc, [c] {
        boost::system::error_code ignored;
        c->socket.close(ignored);
      });
      f.wait();
      throw ClientError(where + "handshake timed out");
    }
    if (const auto e = f.get()) {
      throw ClientError(where + "handshake failed: " + e.message());
    }
    if (!o.tls.fingerprint.empty()) {
      const std::string got = peer_fingerprint(ssl);
      if (got != normalise_fingerprint(o.tls.fingerprint)) {
        asio::post(ioc, [c] {
          boost::system::error_code ignored;
          c->socket.close(ignored);
        });
        throw ClientError(where + "the server's certificate fingerprint " + got +
                          " is not the pinned one");
      }
    }
  }

  Role connect_once() {
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
      asio::post(ioc, [c] {
        boost::system::error_code ignored;
        c->socket.close(ignored);
      });
      connected_f.wait();
      throw ClientError("bridge: connect to " + o.host + ":" + std::to_string(o.port) +
                        " timed out");
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
    const Reply hello = request("hello", {{"protocol", kProtocolVersion}, {"token", o.token}}, {});
    if (!hello) {
      drop_connection();
      throw ClientError("bridge: hello refused: " +
                            (hello.code ? std::string(to_string(*hello.code)) + ": " : "") +
                            hello.message,
                        hello.code);
    }
    const Role r =
        hello.body.value("role", "viewer") == "operator" ? Role::kOperator : Role::kViewer;
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

  Role reconnect_and_replay() {
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

  void reconnect_loop() {
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

  void shutdown() {
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
};

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

Reply Client::request(std::string_view op, const Json& params,
                      std::optional<std::chrono::milliseconds> timeout) {
  return impl_->request(op, params, timeout);
}

Reply Client::request_raw(std::string line, std::optional<std::int64_t> expect_id,
                          std::optional<std::chrono::milliseconds> timeout) {
  line.push_back('\n');
  return impl_->send(line, expect_id, timeout);
}

void Client::set_event_handler(EventHandler h) {
  std::lock_guard lock(impl_->mu);
  impl_->on_event = std::move(h);
}

void Client::set_connection_handler(ConnectionHandler h) {
  std::lock_guard lock(impl_->mu);
  impl_->on_conn = std::move(h);
}

Reply Client::subscribe(const std::vector<std::string>& topics, int rate_hz) {
  Reply r = request("subscribe", {{"topics", topics}, {"rate_hz", rate_hz}});
  if (r) {
    std::lock_guard lock(impl_->mu);
    impl_->sub_topics = topics;
    impl_->sub_rate = rate_hz;
  }
  return r;
}

Reply Client::unsubscribe() {
  {
    std::lock_guard lock(impl_->mu);
    impl_->sub_topics.clear();
  }
  return request("unsubscribe");
}

Reply Client::trace_start(const std::vector<std::string>& vars) {
  Reply r = request("trace.start", {{"vars", vars}});
  if (r) {
    std::lock_guard lock(impl_->mu);
    impl_->trace_vars = vars;
  }
  return r;
}

Reply Client::trace_stop() {
  {
    std::lock_guard lock(impl_->mu);
    impl_->trace_vars.clear();
  }
  return request("trace.stop");
}

Reply Client::upload_program(std::span<const machining::MotionBlock> blocks,
                             std::size_t chunk_blocks) {
  Reply r = request("program.begin", {{"blocks", blocks.size()}});
  if (!r) {
    return r;
  }
  std::size_t first = 0;
  while (first < blocks.size()) {
    Json chunk = Json::array();
    std::size_t bytes = 0;
    std::size_t i = first;
    for (; i < blocks.size() && i - first < std::max<std::size_t>(chunk_blocks, 1); ++i) {
      Json b = to_json(blocks[i]);
      bytes += b.dump().size() + 1;
      chunk.push_back(std::move(b));
      if (bytes > kChunkBytes) {
        ++i;
        break;
      }
    }
    r = request("program.chunk", {{"first", first}, {"blocks", std::move(chunk)}});
    if (!r) {
      request("program.abort");
      return r;
    }
    first = i;
  }
  r = request("program.commit", {{"checksum", format_checksum(program_checksum(blocks))}});
  return r;
}

Role Client::reconnect() { return impl_->reconnect_and_replay(); }

std::uint64_t Client::connections() const noexcept { return impl_->connections.load(); }

}  // namespace edm::bridge
