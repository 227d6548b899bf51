#include "edm/hmi/web_session.hpp"

#include <atomic>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>
#include <cstdio>
#include <string_view>

#include "edm/hmi/web_command.hpp"
#include "edm/hmi/web_outbox.hpp"

namespace edm::hmi {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace asio = boost::asio;
using bridge::Json;
using Clock = std::chrono::steady_clock;

namespace {

/// How often a log-in that waits (for edmplc, or behind another log-in of its address) looks
/// again, and how long it may wait in all: then the socket is closed ("try again later") and the
/// page, which keeps its token, opens a new one.
constexpr auto kLoginRetry = std::chrono::milliseconds(250);
constexpr auto kLoginWait = std::chrono::seconds(30);

std::uint64_t next_session_id() {
  static std::atomic<std::uint64_t> next{1};
  return next++;
}

WebHub::Lane hub_lane(PageLane lane) {
  return lane == PageLane::kMachine ? WebHub::Lane::kMachine : WebHub::Lane::kProgram;
}

/// `Stream`: beast::tcp_stream (WS) or beast::ssl_stream<beast::tcp_stream> (WSS), after the HTTP
/// session has read the upgrade request.
template <class Stream>
class WsSession : public WebSink, public std::enable_shared_from_this<WsSession<Stream>> {
  using std::enable_shared_from_this<WsSession<Stream>>::shared_from_this;
  using std::enable_shared_from_this<WsSession<Stream>>::weak_from_this;

 public:
  WsSession(Stream stream, WebHub& hub, WebPeer peer)
      : ws_(std::move(stream)),
        hub_(hub),
        hub_alive_(hub.alive_token()),
        peer_(std::move(peer)),
        login_timer_(ws_.get_executor()),
        retry_timer_(ws_.get_executor()),
        outbox_(hub.queued_bytes()) {}

  ~WsSession() override {
    if (hub_alive_.expired()) return;  // shutdown: the hub went first (edmhmi serve's order)
    if (checking_) hub_.login_throttle().on_abandon(peer_.address);
    hub_.manual().drop(id_);
    hub_.detach(this);
  }

  void run(beast::http::request<beast::http::string_body> req) {
    // Beast's server defaults (pings, 300 s idle), but a close handshake the peer does not answer
    // ends after 5 s instead of 30.
    auto timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
    timeouts.handshake_timeout = std::chrono::seconds(5);
    ws_.set_option(timeouts);
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(beast::http::field::server, "edmhmi"); }));
    ws_.read_message_max(kMaxWebMessageBytes);
    login_timer_.expires_after(kLoginTimeout);
    login_timer_.async_wait([weak = weak_from_this()](beast::error_code ec) {
      const auto self = weak.lock();
      if (ec || !self || self->role_ || self->login_asked_ || self->closing_) return;
      // No log-in in time: a client that may not answer a close handshake either.
      self->hard_close();
    });
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->guarded([&] {
        self->hub_.watch(self);
        self->send_reply(self->hub_.bridge_message());  // "waiting for edmplc …" or up
        self->do_read();
      });
    });
  }

  void send(std::shared_ptr<const std::string> message) override {
    push(std::move(message), WebOutbox::Kind::kFrame);
  }

 private:
  /// Runs a handler's body; whatever it throws ends this socket only.
  template <class F>
  void guarded(F&& f) {
    try {
      f();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "edmhmi serve: socket %llu closed: %s\n",
                   static_cast<unsigned long long>(id_), e.what());
      hard_close();
    } catch (...) {
      hard_close();
    }
  }

  void push(std::shared_ptr<const std::string> message, WebOutbox::Kind kind) {
    if (closing_ || close_reason_) return;
    switch (outbox_.push(std::move(message), kind)) {
      case WebOutbox::Push::kStartWrite: stall_since_.reset(); return do_write();
      case WebOutbox::Push::kQueued: stall_since_.reset(); return;
      case WebOutbox::Push::kDropped:
        hub_.count_drop();
        if (!stall_since_) stall_since_ = Clock::now();
        if (Clock::now() - *stall_since_ > kStallTimeout) {
          hub_.count_slow_disconnect();
          hard_close();  // a stalled writer: no close handshake
        }
        return;
      case WebOutbox::Push::kOverflow:  // asks, and does not read what it asked for
        hub_.count_reply_overflow();
        hub_.count_slow_disconnect();
        return hard_close();
    }
  }

  void send_reply(std::string text) {
    push(std::make_shared<const std::string>(std::move(text)), WebOutbox::Kind::kReply);
  }
  void send_json(const Json& j) {
    if (!j.is_null()) send_reply(page_text(j));
  }

  void do_read() {
    if (closing_) return;
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->guarded([&] { self->on_read(ec); });
    });
  }

  void on_read(beast::error_code ec) {
    if (ec) {  // closed, timed out or too large: the session ends, and a jog it held stops now
      closing_ = true;
      retry_timer_.cancel();  // a log-in that waits is given up
      hub_.manual().drop(id_);
      return;
    }
    if (!ws_.got_text()) {
      return close(websocket::close_code::unknown_data, "text messages only");
    }
    if (login_asked_ && !role_) {  // nothing but the log-in until it is answered
      return close(websocket::close_code::policy_error, "wait for the log-in's answer");
    }
    const std::string text = beast::buffers_to_string(buffer_.data());
    buffer_.consume(buffer_.size());
    if (buffer_.capacity() > 64 * 1024) buffer_.shrink_to_fit();  // a 2 MiB upload is not kept
    PageAction a = page_action(text, role_);
    switch (a.kind) {
      case PageAction::Kind::kReply: send_json(a.reply); break;
      case PageAction::Kind::kClose:
        send_json(a.reply);
        return close(websocket::close_code::policy_error, "log in first");
      case PageAction::Kind::kLogin:
        on_login(std::move(a.token));  // reading goes on: a socket closed meanwhile is seen
        break;
      case PageAction::Kind::kHeld:
        if (*role_ == bridge::Role::kOperator) hub_.manual().held(id_);
        break;
      case PageAction::Kind::kRun: run_command(std::move(a.command)); break;
    }
    do_read();
  }

  void on_login(std::string token) {
    login_asked_ = true;
    login_timer_.cancel();
    login_deadline_ = Clock::now() + kLoginWait;
    token_ = std::move(token);
    try_login();
  }

  /// Checks the token when edmplc is there and the throttle of this address admits it; else
  /// looks again later (the socket meanwhile knows edmplc's state from the hub).
  void try_login() {
    if (closing_ || close_reason_) return;
    const auto now = Clock::now();
    if (now > login_deadline_) {
      return close(websocket::close_code::try_again_later,
                   hub_.ready() ? "log-in throttled" : "edmplc is not there");
    }
    std::optional<Clock::time_point> when;
    if (hub_.ready()) when = hub_.login_throttle().admit_at(peer_.address, now);
    if (!when || *when > now) {
      retry_timer_.expires_at(when ? *when : now + kLoginRetry);
      retry_timer_.async_wait([weak = weak_from_this()](beast::error_code ec) {
        if (const auto self = weak.lock(); self && !ec) self->guarded([&] { self->try_login(); });
      });
      return;
    }
    hub_.login_throttle().begin(peer_.address);
    checking_ = true;
    // The session holds no read or write while the token is checked: the work keeps it alive.
    const bool queued = hub_.post_work(
        WebHub::Lane::kLogin,
        [self = shared_from_this(), token = token_, peer = peer_.address, &hub = hub_] {
          std::optional<bridge::Role> role;
          std::optional<bridge::ErrorCode> code;
          std::string why;
          try {
            role = hub.authenticate(token, peer);
          } catch (const bridge::ClientError& e) {
            why = e.what();
            code = e.code();
          } catch (const std::exception& e) {
            why = e.what();
          }
          asio::post(hub.io(), [self, role, code, why] {
            self->guarded([&] { self->on_login_checked(role, code, why); });
          });
        });
    if (!queued) {
      checking_ = false;
      hub_.login_throttle().on_abandon(peer_.address);
      close(websocket::close_code::try_again_later, "server busy");
    }
  }

  void on_login_checked(std::optional<bridge::Role> role, std::optional<bridge::ErrorCode> code,
                        const std::string& why) {
    checking_ = false;
    if (hub_alive_.expired()) return;
    // The throttle learns the outcome even when the socket closed meanwhile: closing does not
    // dodge it.
    LoginThrottle& throttle = hub_.login_throttle();
    if (role) {
      throttle.on_success(peer_.address);
      if (closing_) return;
      token_.clear();
      role_ = role;
      hub_.attach(shared_from_this());
      return send_reply(hub_.welcome(*role));
    }
    if (code == bridge::ErrorCode::kUnauthorized) {
      const auto delay = throttle.on_failure(peer_.address, Clock::now());
      hub_.count_login_failure();
      send_json({{"t", "login_failed"},
                 {"message", why},
                 {"retry_after_ms", static_cast<std::int64_t>(delay.count())}});
      return close(websocket::close_code::policy_error, "log-in refused");
    }
    throttle.on_abandon(peer_.address);
    if (closing_) return;
    if (!code) {  // edmplc did not answer (it went away): again, a little later
      retry_timer_.expires_after(kLoginRetry);
      retry_timer_.async_wait([weak = weak_from_this()](beast::error_code ec) {
        if (const auto self = weak.lock(); self && !ec) self->guarded([&] { self->try_login(); });
      });
      return;
    }
    send_json({{"t", "login_failed"}, {"message", why}});
    close(websocket::close_code::try_again_later, "log-in not checked");
  }

  void run_command(PageCommand cmd) {
    const PageLane lane = page_op_info(cmd.op).lane;
    if (lane == PageLane::kInline) return send_json(run_page_command(hub_, cmd, id_));
    if (in_flight_ >= kMaxInFlight) {
      return send_json(page_refusal(cmd.id, "busy", "too many commands in progress"));
    }
    ++in_flight_;
    const Json id = cmd.id;
    const bool queued = hub_.post_work(
        hub_lane(lane), [weak = weak_from_this(), cmd = std::move(cmd), owner = id_, &hub = hub_] {
          Json out = run_page_command(hub, cmd, owner);
          const bool ok = out.is_object() && out.contains("ok") && out["ok"] == true;
          const bool job_changed = ok && (cmd.op == PageOp::kUpload || cmd.op == PageOp::kStart ||
                                          cmd.op == PageOp::kStartFrom);
          asio::post(hub.io(), [weak, out = std::move(out), job_changed, &hub] {
            if (const auto self = weak.lock()) {
              self->guarded([&] {
                if (job_changed) hub.broadcast_job();
                --self->in_flight_;
                self->send_json(out);
              });
            }
          });
        });
    if (!queued) {
      --in_flight_;
      send_json(page_refusal(id, "busy", "server busy"));
    }
  }

  void do_write() {
    ws_.text(true);
    ws_.async_write(asio::buffer(outbox_.front()),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      if (ec) {
                        self->closing_ = true;
                        self->outbox_.clear();
                        return;
                      }
                      if (self->outbox_.pop()) {
                        self->do_write();
                      } else if (self->close_reason_) {
                        self->do_close();
                      }
                    });
  }

  /// Closes after the queued messages (e.g. the reason a log-in failed) are written.
  void close(websocket::close_code code, const char* reason) {
    if (closing_ || close_reason_) return;
    close_reason_ = websocket::close_reason(code, reason);
    if (outbox_.empty()) do_close();
  }

  void do_close() {
    closing_ = true;
    ws_.async_close(*close_reason_, [self = shared_from_this()](beast::error_code) {});
  }

  /// Drops the TCP connection at once (no close handshake to wait for).
  void hard_close() {
    closing_ = true;
    retry_timer_.cancel();
    beast::get_lowest_layer(ws_).close();
  }

  websocket::stream<Stream> ws_;
  WebHub& hub_;
  std::weak_ptr<const bool> hub_alive_;  // WebHub::alive_token()
  WebPeer peer_;
  asio::steady_timer login_timer_, retry_timer_;
  beast::flat_buffer buffer_;
  WebOutbox outbox_;
  std::optional<bridge::Role> role_;
  std::string token_;  // while the log-in waits
  std::optional<Clock::time_point> stall_since_;
  std::optional<websocket::close_reason> close_reason_;
  Clock::time_point login_deadline_{};
  int in_flight_{0};
  bool login_asked_{false};
  bool checking_{false};  // a log-in of this socket is being checked (the throttle knows)
  bool closing_{false};
  const std::uint64_t id_{next_session_id()};  // the owner of a jog this browser holds
};

}  // namespace

void start_web_socket(beast::tcp_stream stream,
                      beast::http::request<beast::http::string_body> request, WebHub& hub,
                      WebPeer peer) {
  std::make_shared<WsSession<beast::tcp_stream>>(std::move(stream), hub, std::move(peer))
      ->run(std::move(request));
}

void start_web_socket(beast::ssl_stream<beast::tcp_stream> stream,
                      beast::http::request<beast::http::string_body> request, WebHub& hub,
                      WebPeer peer) {
  std::make_shared<WsSession<beast::ssl_stream<beast::tcp_stream>>>(std::move(stream), hub,
                                                                    std::move(peer))
      ->run(std::move(request));
}

}  // namespace edm::hmi
