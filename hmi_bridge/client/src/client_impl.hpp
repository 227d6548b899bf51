#pragma once
// The inside of edm::bridge::Client, one job per file:
//   client_line.cpp     line transport: framing (async_read_until), write queue, keep-alive,
//                       losing the connection
//   client_request.cpp  request and reply: ids, waiting, matching replies, dispatching events
//   client_connect.cpp  dialling, TLS, hello, reconnect with replay, the auto-reconnect loop
//   client_upload.cpp   program.begin / chunk / commit
//   client_tls.cpp      how the server's certificate is verified
//
// Threads: Conn is touched only on the I/O thread once started. Impl's state under `mu` may be
// touched from any thread; members marked "I/O thread" run only there. Not RT-safe.

#include <atomic>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/steady_timer.hpp>
#include <condition_variable>
#include <deque>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "edm/bridge/client.hpp"

namespace edm::bridge {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

/// One TCP connection, with TLS over it when the options ask; touched only on the I/O thread
/// once started.
struct Conn {
  explicit Conn(asio::io_context& ioc) : socket(ioc), keepalive(ioc) {}
  tcp::socket socket;
  std::shared_ptr<asio::ssl::context> tls_ctx;
  std::optional<asio::ssl::stream<tcp::socket&>> tls;
  asio::steady_timer keepalive;
  std::string rx;          // read and not yet framed: at most max_line_bytes + 1
  bool discarding{false};  // inside a line longer than max_line_bytes: dropped to its end
  std::deque<std::string> wq;
  bool writing{false};
  bool dead{false};
  std::chrono::steady_clock::time_point last_write{};
};

using Promise = std::promise<Reply>;

/// A reply the transport made up (timeout, disconnected, not connected): code empty.
Reply transport_error(std::string message);

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

  Impl();

  /// Runs f() under mu.
  template <class F>
  void locked(F&& f) {
    std::lock_guard lock(mu);
    f();
  }

  [[nodiscard]] bool on_io_thread() const {
    return std::this_thread::get_id() == io_thread.get_id();
  }

  // ---- line transport (client_line.cpp), I/O thread ----
  void start_read(const std::shared_ptr<Conn>& c);
  void on_line(const std::shared_ptr<Conn>& c, boost::system::error_code ec, std::size_t n);
  void write(const std::shared_ptr<Conn>& c, std::string line);
  void do_write(const std::shared_ptr<Conn>& c);
  void arm_keepalive(const std::shared_ptr<Conn>& c);
  /// The connection is gone: fail what waits, tell the handler, wake the reconnector.
  void lose(const std::shared_ptr<Conn>& c, const std::string& why);
  /// Any thread but the I/O thread: loses the current connection and waits until it is lost.
  void drop_connection();

  // ---- request and reply (client_request.cpp) ----
  /// I/O thread: one received line, a reply (to its waiting request) or an event.
  void handle_line(const std::string& line);
  Reply wait(const std::shared_ptr<Promise>& p, std::optional<std::chrono::milliseconds> timeout,
             std::optional<std::int64_t> id);
  Reply send(const std::string& line, std::optional<std::int64_t> id,
             std::optional<std::chrono::milliseconds> timeout);
  Reply request(std::string_view op, const Json& params,
                std::optional<std::chrono::milliseconds> timeout);

  // ---- connecting (client_connect.cpp), any thread but the I/O thread ----
  void tls_handshake(const std::shared_ptr<Conn>& c, const ClientOptions& o);
  Role connect_once();
  Role reconnect_and_replay();
  void reconnect_loop();
  void shutdown();
};

}  // namespace edm::bridge
