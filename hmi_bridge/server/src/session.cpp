// One client connection: handshake, hello deadline, line framing, read timeout, a write queue
// bounded in messages and bytes, the status timer, and a graceful close.
#include <spdlog/spdlog.h>

#include <boost/asio/buffer.hpp>
#include <boost/asio/post.hpp>

#include "server_impl.hpp"

namespace edm::bridge {

namespace {

bool ignorable(const boost::system::error_code& ec) {
  return ec == asio::error::operation_aborted || ec == asio::error::eof ||
         ec == asio::error::connection_reset || ec == asio::error::bad_descriptor ||
         ec == asio::error::broken_pipe;
}

// Beast-style: a closed connection or a cancelled operation is not worth a log line.
void fail(const boost::system::error_code& ec, const char* what, std::uint64_t id) {
  if (!ignorable(ec)) {
    spdlog::debug("bridge: session {}: {}: {}", id, what, ec.message());
  }
}

}  // namespace

Session::Session(Server::Impl& server, std::unique_ptr<Transport> transport, std::uint64_t id)
    : server_(server),
      transport_(std::move(transport)),
      id_(id),
      address_(transport_->peer_address()),
      peer_(transport_->peer()),
      read_timer_(server.ioc),
      hello_timer_(server.ioc),
      throttle_timer_(server.ioc),
      status_timer_(server.ioc) {
  loopback_ = is_loopback_address(address_);
}

std::string Session::log_name() const {
  std::string n = "session " + std::to_string(id_) + " (" + peer_;
  if (!via_.empty()) {
    n += " via=";
    rt::append_log_quoted(n, via_);
  }
  n += ")";
  return n;
}

void Session::start() {
  arm_hello_timer();
  transport_->async_handshake(
      [self = shared_from_this()](boost::system::error_code ec) { self->on_handshake(ec); });
}

void Session::on_handshake(boost::system::error_code ec) {
  if (closed_) {
    return;
  }
  if (ec) {
    log(spdlog::level::info, "TLS handshake failed: {}", ec.message());
    close();
    return;
  }
  handshaken_ = true;
  arm_read_timer();
  do_read();
}

void Session::close() {
  if (closed_) {
    return;
  }
  closed_ = true;
  transport_->close();
  read_timer_.cancel();
  hello_timer_.cancel();
  throttle_timer_.cancel();
  status_timer_.cancel();
  queue_.clear();
  queued_bytes_ = 0;
  server_.remove(*this);
}

void Session::async_close() {
  asio::post(server_.ioc, [self = shared_from_this()] { self->close(); });
}

void Session::close_after_flush() {
  close_after_flush_ = true;
  if (!writing_ && queue_.empty()) {
    linger_close();
  }
}

// After the last reply: end gracefully (FIN and drain, or TLS close_notify) so the reply is
// not lost to a reset, and close at the latest kLinger later.
void Session::linger_close() {
  if (closed_ || lingering_) {
    return;
  }
  lingering_ = true;
  constexpr std::chrono::milliseconds kLinger{1000};
  read_timer_.expires_after(kLinger);
  read_timer_.async_wait([self = shared_from_this()](boost::system::error_code e) {
    if (!e) {
      self->close();
    }
  });
  if (reading_) {
    transport_->cancel();  // on_read starts the shutdown once the read has let go
  } else {
    start_shutdown();
  }
}

void Session::start_shutdown() {
  transport_->async_shutdown(
      [self = shared_from_this()](boost::system::error_code) { self->close(); });
}

bool Session::wants(std::string_view topic) const {
  if (closed_ || !role_) {
    return false;
  }
  if (topic == kTopicAlarm) {
    return sub_alarm_;
  }
  if (topic == kTopicProgress) {
    return sub_progress_;
  }
  return topic == kTopicStatus && sub_status_;
}

void Session::arm_read_timer() {
  read_timer_.expires_after(server_.opt.read_timeout);
  read_timer_.async_wait([self = shared_from_this()](boost::system::error_code ec) {
    if (ec || self->closed_ || self->lingering_) {
      return;
    }
    self->server_.counters.timeouts.fetch_add(1, std::memory_order_relaxed);
    self->log(spdlog::level::info, "no request for {} ms, closing",
              self->server_.opt.read_timeout.count());
    self->close();
  });
}

// A connection that has not said a valid hello this soon is closed: unauthenticated sockets
// cannot hold a slot for long.
void Session::arm_hello_timer() {
  hello_timer_.expires_after(server_.opt.hello_timeout);
  hello_timer_.async_wait([self = shared_from_this()](boost::system::error_code ec) {
    if (ec || self->closed_ || self->role_ || self->lingering_ || self->deferred_hello_) {
      return;  // a hello that came in time and waits for the throttle is not timed out
    }
    self->server_.counters.hello_timeouts.fetch_add(1, std::memory_order_relaxed);
    self->log(spdlog::level::info, "no valid hello within {} ms, closing",
              self->server_.opt.hello_timeout.count());
    self->close();
  });
}

void Session::do_read() {
  if (closed_ || reading_ || !handshaken_) {
    return;
  }
  if (lingering_) {
    return;  // the shutdown drains what the client still sends
  }
  if (queue_full()) {
    read_paused_ = true;  // the client is not reading its replies: stop reading its requests
    return;
  }
  reading_ = true;
  transport_->async_read_some(
      asio::buffer(rx_), [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
        self->on_read(ec, n);
      });
}

void Session::on_read(boost::system::error_code ec, std::size_t n) {
  reading_ = false;
  if (closed_) {
    return;
  }
  if (lingering_) {
    start_shutdown();
    return;
  }
  if (ec) {
    fail(ec, "read", id_);
    close();
    return;
  }
  if (deferred_hello_) {
    do_read();  // waiting for the throttle: what else the client sends is dropped, but its
    return;     // closing the connection is seen (and frees the slot) at once
  }
  input_.assign(rx_.data(), n);
  process_input();
}

// Frames and runs the requests of the last read, but only while the reply queue has room: a
// client that pipelines requests without reading replies stops being read, mid-read if need
// be, so its replies never take more than about queue_bytes.
// Framed by hand, not with asio::async_read_until as the client is: the session reads through
// the type-erased Transport (TCP, TLS, the fuzzer's in-memory stream), which is no
// AsyncReadStream; a too-long line is answered too_large and skipped to its '\n' while the
// session goes on, and read_until's not_found would leave that skipping to code like this anyway.
void Session::process_input() {
  const std::size_t limit = role_ ? server_.opt.max_line_bytes : kPreAuthLineBytes;
  std::size_t used = 0;
  while (used < input_.size() && !closed_ && !close_after_flush_ && !deferred_hello_ &&
         !queue_full()) {
    const std::string_view rest = std::string_view(input_).substr(used);
    const auto nl = rest.find('\n');
    const std::string_view part = rest.substr(0, nl);
    used += nl == std::string_view::npos ? rest.size() : nl + 1;
    if (discarding_) {
      discarding_ = nl == std::string_view::npos;  // until the too-long line has ended
    } else if (line_.size() + part.size() > limit) {
      server_.counters.errors.fetch_add(1, std::memory_order_relaxed);
      send_reply(make_error(nullptr, ErrorCode::kTooLarge,
                            "line longer than " + std::to_string(limit) + " bytes; skipped"));
      line_.clear();
      line_.shrink_to_fit();
      discarding_ = nl == std::string_view::npos;
    } else if (nl == std::string_view::npos) {
      line_.append(part);
    } else if (line_.empty()) {
      handle_line(part);
    } else {
      line_.append(part);
      std::string line = std::move(line_);
      line_.clear();
      handle_line(line);
    }
  }
  input_.erase(0, used);
  if (closed_) {
    return;
  }
  if (deferred_hello_ || close_after_flush_) {
    input_.clear();  // a throttled hello's followers, or requests of an ending session: dropped
  }
  if (!input_.empty()) {
    read_paused_ = true;  // resumed by on_write once the queue has drained
    return;
  }
  do_read();
}

void Session::handle_line(std::string_view line) {
  if (close_after_flush_ || closed_) {
    return;  // the session is ending: later requests get no reply
  }
  if (!line.empty() && line.back() == '\r') {
    line.remove_suffix(1);
  }
  // Any line, a blank keep-alive included, is activity (docs/protocol.md); it does not extend
  // the hello deadline.
  arm_read_timer();
  if (line.find_first_not_of(" \t") == std::string_view::npos) {
    return;
  }
  server_.counters.requests.fetch_add(1, std::memory_order_relaxed);
  ErrorCode code{};
  std::string message;
  Json id;
  auto req = parse_request(line, code, message, id);
  OpResult r;
  if (!req) {
    r.reply = make_error(id, code, message);
  } else {
    try {
      r = run_op(*this, *req);
    } catch (const std::exception& e) {  // a bug or bad_alloc must not take the server down
      log(spdlog::level::err, "op {} failed: {}", rt::log_quoted(req->op),
          rt::log_quoted(e.what(), 256));
      r.reply = make_error(req->id, ErrorCode::kBadRequest, "internal error");
    }
  }
  if (r.retry_at) {
    deferred_hello_ = std::string(line);
    throttle_timer_.expires_at(*r.retry_at);
    throttle_timer_.async_wait([self = shared_from_this()](boost::system::error_code ec) {
      if (ec || self->closed_ || !self->deferred_hello_) {
        return;
      }
      std::string again = std::move(*self->deferred_hello_);
      self->deferred_hello_.reset();
      self->handle_line(again);
      self->do_read();
    });
    return;
  }
  if (r.reply.is_null()) {
    return;
  }
  if (!r.reply.value("ok", false)) {
    server_.counters.errors.fetch_add(1, std::memory_order_relaxed);
  }
  send_reply(r.reply);
  if (r.close_after) {
    close_after_flush();
  }
}

void Session::send_reply(const Json& reply) {
  if (closed_) {
    return;
  }
  enqueue(to_line(reply));
}

bool Session::queue_full() const {
  return queue_.size() >= server_.opt.queue_limit || queued_bytes_ >= server_.opt.queue_bytes;
}

void Session::send_event(std::string_view name, Json body) {
  if (closed_ || close_after_flush_ || lingering_ || close_posted_) {
    return;
  }
  if (queue_full()) {
    ++dropped_;
    server_.counters.events_dropped.fetch_add(1, std::memory_order_relaxed);
    const auto now = SteadyClock::now();
    if (!stalled_since_) {
      stalled_since_ = now;
    } else if (now - *stalled_since_ > server_.opt.stall_timeout) {
      server_.counters.slow_disconnects.fetch_add(1, std::memory_order_relaxed);
      log(spdlog::level::warn, "not reading for {} ms ({} events dropped); disconnecting",
          server_.opt.stall_timeout.count(), dropped_);
      // Posted: the caller is a broadcast loop, and closing takes the session out of the
      // server's registry. Once: the events until it runs are not this session's any more.
      close_posted_ = true;
      async_close();
    }
    return;
  }
  server_.counters.events_sent.fetch_add(1, std::memory_order_relaxed);
  enqueue(to_line(make_event(name, ++seq_, body)));
}

void Session::enqueue(std::string msg) {
  queued_bytes_ += msg.size();
  queue_.push_back(std::move(msg));
  if (queued_bytes_ > server_.counters.queue_bytes_peak.load(std::memory_order_relaxed)) {
    server_.counters.queue_bytes_peak.store(queued_bytes_, std::memory_order_relaxed);
  }
  if (!writing_) {
    do_write();
  }
}

void Session::do_write() {
  if (closed_ || writing_ || queue_.empty()) {  // one write in flight
    return;
  }
  writing_ = true;
  transport_->async_write(asio::buffer(queue_.front()),
                          [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
                            self->on_write(ec, n);
                          });
}

void Session::on_write(boost::system::error_code ec, std::size_t /*n*/) {
  writing_ = false;
  if (closed_) {
    return;
  }
  if (ec) {
    fail(ec, "write", id_);
    close();
    return;
  }
  if (!queue_.empty()) {
    queued_bytes_ -= queue_.front().size();
    queue_.pop_front();
  }
  if (!queue_full()) {
    stalled_since_.reset();
  }
  if (queue_.empty() && close_after_flush_) {
    linger_close();
    return;
  }
  if (read_paused_ && queue_.size() <= server_.opt.queue_limit / 2 &&
      queued_bytes_ <= server_.opt.queue_bytes / 2) {
    read_paused_ = false;
    process_input();
  }
  do_write();
}

void Session::start_status_timer() {
  status_timer_.cancel();
  ++status_gen_;
  if (!sub_status_ || rate_hz_ <= 0) {
    return;
  }
  // A handler of the previous chain may already be queued (expired before the cancel): the
  // generation makes it a no-op, so one chain runs per session.
  const std::uint64_t gen = ++status_gen_;
  next_status_ = SteadyClock::now();
  status_timer_.expires_at(next_status_);
  status_timer_.async_wait([self = shared_from_this(), gen](boost::system::error_code ec) {
    self->on_status_tick(ec, gen);
  });
}

void Session::on_status_tick(boost::system::error_code ec, std::uint64_t gen) {
  if (ec || closed_ || gen != status_gen_ || !sub_status_ || rate_hz_ <= 0) {
    return;
  }
  StatusMessage m = server_.status_message();
  m.dropped = dropped_;
  send_event(kTopicStatus, to_json(m));
  // Absolute deadlines keep the rate exact; after a stall, skip the missed ticks (no burst).
  const auto period = std::chrono::duration_cast<SteadyClock::duration>(
      std::chrono::duration<double>(1.0 / rate_hz_));
  next_status_ += period;
  const auto now = SteadyClock::now();
  if (next_status_ < now) {
    next_status_ = now + period;
  }
  status_timer_.expires_at(next_status_);
  status_timer_.async_wait([self = shared_from_this(), gen](boost::system::error_code e) {
    self->on_status_tick(e, gen);
  });
}

}  // namespace edm::bridge
