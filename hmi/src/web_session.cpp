#include "edm/hmi/web_session.hpp"

#include <atomic>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>
#include <cstdio>
#include <deque>
#include <set>
#include <string_view>

namespace edm::hmi {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace asio = boost::asio;
using bridge::Json;
using Clock = std::chrono::steady_clock;

namespace {

/// Commands a viewer may send: none of them changes the machine or the job.
const std::set<std::string, std::less<>> kViewerCommands{
    "check", "stats", "var.list", "var.read", "job", "offset.get", "manual.status"};
/// Machine commands relayed as they are.
const std::set<std::string, std::less<>> kMachineOps{"cycle.hold", "cycle.resume", "cycle.stop",
                                                     "estop", "reset"};
/// Manual commands relayed with the fields edmplc checks (values, ranges, the machine's state).
const std::set<std::string, std::less<>> kManualOps{"home", "jog", "jog.stop"};
/// Quick commands on the machine lane; the rest (interpretation, uploads) on the program lane.
const std::set<std::string, std::less<>> kMachineLane{
    "start", "feed.override", "home", "jog", "jog.stop", "jog.hold", "touch", "offset.set"};

Json reply_json(const bridge::Reply& r) { return page_reply(r); }

Json bad_request(const std::string& message) {
  return {{"ok", false}, {"code", "bad_request"}, {"message", message}};
}

std::uint64_t next_session_id() {
  static std::atomic<std::uint64_t> next{1};
  return next++;
}

/// `Stream`: beast::tcp_stream (WS) or beast::ssl_stream<beast::tcp_stream> (WSS), after the HTTP
/// session has read the upgrade request.
template <class Stream>
class WsSession : public WebSink, public std::enable_shared_from_this<WsSession<Stream>> {
  using std::enable_shared_from_this<WsSession<Stream>>::shared_from_this;
  using std::enable_shared_from_this<WsSession<Stream>>::weak_from_this;

 public:
  WsSession(Stream stream, WebHub& hub)
      : ws_(std::move(stream)),
        hub_(hub),
        hub_alive_(hub.alive_token()),
        login_timer_(ws_.get_executor()) {}

  ~WsSession() override {
    if (hub_alive_.expired()) return;  // shutdown: the hub went first (edmhmi serve's order)
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
      if (ec || !self || self->role_ || self->closing_) return;
      // No log-in in time: a client that may not answer a close handshake either.
      self->closing_ = true;
      beast::get_lowest_layer(self->ws_).close();
    });
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->do_read();
    });
  }

  void send(std::shared_ptr<const std::string> message) override {
    if (closing_ || close_reason_) return;
    if (queue_.size() >= kMaxQueued) {
      hub_.count_drop();
      ++dropped_;
      if (!stall_since_) stall_since_ = Clock::now();
      if (Clock::now() - *stall_since_ > kStallTimeout) {
        hub_.count_slow_disconnect();
        closing_ = true;
        beast::get_lowest_layer(ws_).close();  // a stalled writer: no close handshake
      }
      return;
    }
    stall_since_.reset();
    queue_.push_back(std::move(message));
    if (queue_.size() == 1) do_write();
  }

 private:
  void do_read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_read(ec);
    });
  }

  void on_read(beast::error_code ec) {
    if (ec) {  // closed, timed out or too large: the session ends, and a jog it held stops now
      hub_.manual().drop(id_);
      return;
    }
    const std::string text = beast::buffers_to_string(buffer_.data());
    buffer_.consume(buffer_.size());
    const Json msg = Json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (!msg.is_object() || !msg.contains("t") || !msg["t"].is_string()) {
      send_json({{"t", "error"}, {"message", "not a JSON object with \"t\""}});
    } else if (!role_) {
      return on_login(msg);  // reading resumes once the token is checked
    } else if (msg["t"] == "cmd") {
      on_command(msg);
    } else if (msg["t"] == "held") {  // the jog button is still down (no reply)
      if (*role_ == bridge::Role::kOperator) hub_.manual().held(id_);
    } else {
      send_json({{"t", "error"}, {"message", "unknown message type"}});
    }
    do_read();
  }

  void on_login(const Json& msg) {
    if (msg["t"] != "login" || !msg.contains("token") || !msg["token"].is_string()) {
      return close(websocket::close_code::policy_error, "log in first");
    }
    const std::string token = msg["token"].get<std::string>();
    // The session holds no read or write while the token is checked: the work keeps it alive.
    const bool queued =
        hub_.post_work(WebHub::Lane::kLogin, [self = shared_from_this(), token, &hub = hub_] {
          std::optional<bridge::Role> role;
          std::string why;
          try {
            role = hub.authenticate(token);
          } catch (const std::exception& e) {
            why = e.what();
          }
          asio::post(hub.io(), [self, role, why] {
            if (!role) {
              self->send_json({{"t", "login_failed"}, {"message", why}});
              return self->close(websocket::close_code::policy_error, "log-in refused");
            }
            self->role_ = role;
            self->login_timer_.cancel();
            self->hub_.attach(self);
            self->send(std::make_shared<const std::string>(self->hub_.welcome(*role)));
            self->do_read();
          });
        });
    if (!queued) close(websocket::close_code::try_again_later, "server busy");
  }

  void on_command(const Json& msg) {
    const Json id = msg.value("id", Json(nullptr));
    const std::string op = msg.value("op", std::string());
    auto refuse = [&](std::string_view code, std::string_view message) {
      send_json({{"t", "reply"}, {"id", id}, {"ok", false}, {"code", code}, {"message", message}});
    };
    if (*role_ != bridge::Role::kOperator && !kViewerCommands.contains(op)) {
      return refuse("forbidden", "'" + op + "' needs the operator role");
    }
    if (op == "ack") {
      hub_.acknowledge_alarms(msg.value("seq", std::uint64_t{0}));
      return send_json({{"t", "reply"}, {"id", id}, {"ok", true}});
    }
    if (op == "jog.release") {  // at once, never behind a queue
      hub_.manual().release(id_);
      return send_json({{"t", "reply"}, {"id", id}, {"ok", true}});
    }
    if (op == "manual.status" || op == "offset.get") {  // what the hub follows anyway
      const Json body =
          op == "manual.status" ? hub_.manual().manual_json() : hub_.manual().offsets_json();
      return send_json({{"t", "reply"}, {"id", id}, {"ok", !body.is_null()}, {"body", body}});
    }
    if (in_flight_ >= kMaxInFlight) return refuse("busy", "too many commands in progress");
    ++in_flight_;
    const WebHub::Lane lane = kMachineOps.contains(op) || kMachineLane.contains(op)
                                  ? WebHub::Lane::kMachine
                                  : WebHub::Lane::kProgram;
    const std::uint64_t owner = id_;
    const bool queued =
        hub_.post_work(lane, [weak = weak_from_this(), msg, id, op, owner, &hub = hub_] {
          Json out = run_command(hub, op, msg, owner);
          out["t"] = "reply";
          out["id"] = id;
          out["op"] = op;
          const bool job_changed =
              (op == "upload" || op == "start" || op == "start_from") && out.value("ok", false);
          asio::post(hub.io(), [weak, out = std::move(out), job_changed, &hub] {
            if (job_changed) hub.broadcast_job();
            if (const auto self = weak.lock()) {
              --self->in_flight_;
              self->send_json(out);
            }
          });
        });
    if (!queued) {
      --in_flight_;
      refuse("busy", "server busy");
    }
  }

  /// On the worker thread: the blocking part of a command.
  static Json run_command(WebHub& hub, const std::string& op, const Json& msg,
                          std::uint64_t owner) {  // owner: this browser, for a held jog
    const std::string name = msg.value("name", std::string("program.nc"));
    if (op == "check" || op == "upload") {
      if (!msg.contains("text") || !msg["text"].is_string()) {
        return {{"ok", false}, {"code", "bad_request"}, {"message", "text missing"}};
      }
      const std::string& text = msg["text"].get_ref<const std::string&>();
      return op == "check" ? hub.job().check(text, name) : hub.job().upload(text, name);
    }
    if (op == "start") return reply_json(hub.job().start(msg.value("dry_run", false) == true));
    if (op == "start_from") {
      if (!msg.contains("line") || !msg["line"].is_number_integer()) {
        return bad_request("'line' must be a G-code line number");
      }
      std::optional<double> depth;
      if (msg.contains("depth_done") && !msg["depth_done"].is_null()) {
        if (!msg["depth_done"].is_number()) return bad_request("'depth_done' must be mm");
        depth = msg["depth_done"].get<double>();
      }
      return hub.job().start_from(msg["line"].get<std::int32_t>(), depth,
                                  msg.value("dry_run", false) == true);
    }
    if (op == "mdi") {
      if (!msg.contains("line") || !msg["line"].is_string()) return bad_request("'line' missing");
      const std::string& line = msg["line"].get_ref<const std::string&>();
      if (line.size() > 1024 || line.find_first_of("\r\n") != std::string::npos) {
        return bad_request("an MDI command is one line of at most 1024 bytes");
      }
      return hub.job().mdi(line);
    }
    if (kManualOps.contains(op)) {
      Json params = Json::object();
      for (const char* k : {"axes", "axis", "distance"}) {
        if (msg.contains(k)) params[k] = msg[k];
      }
      if (op == "jog.stop") hub.manual().release_any();
      return reply_json(hub.client().request(op, params));
    }
    if (op == "jog.hold") {  // continuous: the hub refreshes it while "held" comes
      if (!msg.contains("axis") || !msg["axis"].is_string() || !msg.contains("velocity") ||
          !msg["velocity"].is_number()) {
        return bad_request("jog.hold needs 'axis' and 'velocity' (mm/s)");
      }
      return hub.manual().hold(owner, msg["axis"].get<std::string>(),
                               msg["velocity"].get<double>());
    }
    if (op == "touch") {
      if (!msg.contains("target") || !msg["target"].is_string()) {
        return bad_request("'target' missing");
      }
      std::string set;
      if (msg.contains("set") && msg["set"].is_string()) set = msg["set"].get<std::string>();
      return hub.manual().touch(msg["target"].get<std::string>(), set);
    }
    if (op == "offset.set") {
      Json params = Json::object();
      for (const char* k : {"frame", "x", "y", "z"}) {
        if (msg.contains(k)) params[k] = msg[k];
      }
      return hub.manual().offset_set(params);
    }
    if (op == "job") return {{"ok", true}, {"body", hub.job().snapshot()}};
    if (kMachineOps.contains(op)) return reply_json(hub.client().request(op));
    if (op == "feed.override") {  // edmplc checks the value (0..150) and the role
      Json params = Json::object();
      if (msg.contains("percent")) params["percent"] = msg["percent"];
      return reply_json(hub.client().request(op, params));
    }
    if (op == "stats") {
      Json r = reply_json(hub.client().request("tasks.stats"));
      const WebHub::Counters c = hub.counters();
      r["web"] = {{"frames", c.frames},
                  {"browsers", c.browsers},
                  {"frames_dropped", c.frames_dropped},
                  {"slow_disconnects", c.slow_disconnects}};
      return r;
    }
    if (op == "var.list" || op == "var.read" || op == "var.write" || op == "var.force" ||
        op == "var.unforce") {
      Json params = Json::object();
      for (const char* k : {"prefix", "names", "name", "value"}) {
        if (msg.contains(k)) params[k] = msg[k];
      }
      return reply_json(hub.client().request(op, params));
    }
    return {{"ok", false}, {"code", "unknown_op"}, {"message", "unknown command '" + op + "'"}};
  }

  void send_json(const Json& j) {
    send(std::make_shared<const std::string>(
        j.dump(-1, ' ', false, Json::error_handler_t::replace)));
  }

  void do_write() {
    ws_.text(true);
    ws_.async_write(asio::buffer(*queue_.front()),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      if (ec) {
                        self->closing_ = true;
                        self->queue_.clear();
                        return;
                      }
                      self->queue_.pop_front();
                      if (!self->queue_.empty()) {
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
    if (queue_.empty()) do_close();
  }

  void do_close() {
    closing_ = true;
    ws_.async_close(*close_reason_, [self = shared_from_this()](beast::error_code) {});
  }

  websocket::stream<Stream> ws_;
  WebHub& hub_;
  std::weak_ptr<const bool> hub_alive_;  // WebHub::alive_token()
  asio::steady_timer login_timer_;
  beast::flat_buffer buffer_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  std::optional<bridge::Role> role_;
  std::optional<Clock::time_point> stall_since_;
  std::optional<websocket::close_reason> close_reason_;
  std::uint64_t dropped_{0};
  int in_flight_{0};
  bool closing_{false};
  const std::uint64_t id_{next_session_id()};  // the owner of a jog this browser holds
};

}  // namespace

void start_web_socket(beast::tcp_stream stream,
                      beast::http::request<beast::http::string_body> request, WebHub& hub) {
  std::make_shared<WsSession<beast::tcp_stream>>(std::move(stream), hub)->run(std::move(request));
}

void start_web_socket(beast::ssl_stream<beast::tcp_stream> stream,
                      beast::http::request<beast::http::string_body> request, WebHub& hub) {
  std::make_shared<WsSession<beast::ssl_stream<beast::tcp_stream>>>(std::move(stream), hub)
      ->run(std::move(request));
}

}  // namespace edm::hmi
