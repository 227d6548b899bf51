// One client connection: line framing, read timeout, bounded write queue, status timer.
#include <spdlog/spdlog.h>

#include <boost/asio/bind_executor.hpp>
#include <boost/asio/buffer.hpp>
#include <boost/asio/write.hpp>

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

Session::Session(Server::Impl& server, tcp::socket socket, std::uint64_t id)
    : server_(server),
      socket_(std::move(socket)),
      strand_(asio::make_strand(server.ioc)),
      id_(id),
      read_timer_(strand_),
      status_timer_(strand_) {
  boost::system::error_code ec;
  const auto ep = socket_.remote_endpoint(ec);
  if (!ec) {
    loopback_ = is_loopback_address(ep.address().to_string());
    peer_ = ep.address().to_string() + ":" + std::to_string(ep.port());
  }
  socket_.set_option(tcp::no_delay(true), ec);
  if (server.opt.send_buffer_bytes > 0) {
    socket_.set_option(asio::socket_base::send_buffer_size(server.opt.send_buffer_bytes), ec);
  }
}

void Session::start() {
  asio::dispatch(strand_, [self = shared_from_this()] {
    self->arm_read_timer();
    self->do_read();
  });
}

void Session::close() {
  if (closed_) {
    return;
  }
  closed_ = true;
  boost::system::error_code ec;
  socket_.shutdown(tcp::socket::shutdown_both, ec);
  socket_.close(ec);
  read_timer_.cancel();
  status_timer_.cancel();
  queue_.clear();
  server_.remove(this);
}

void Session::async_close() {
  asio::dispatch(strand_, [self = shared_from_this()] { self->close(); });
}

void Session::refuse(ErrorCode code, std::string message) {
  refusal_.emplace(code, std::move(message));
}

void Session::close_after_flush() {
  close_after_flush_ = true;
  if (!writing_ && queue_.empty()) {
    linger_close();
  }
}

// Half-close after the last reply: send FIN, then drain what the client still sends until it
// closes too (or kLinger passes). Closing with unread input would send an RST, and the client's
// TCP stack may then drop the reply it has not read yet (a refused hello would read as a plain
// disconnect instead of `busy` / `unauthorized`).
void Session::linger_close() {
  if (closed_ || lingering_) {
    return;
  }
  lingering_ = true;
  boost::system::error_code ec;
  socket_.shutdown(tcp::socket::shutdown_send, ec);
  if (ec) {
    close();
    return;
  }
  constexpr std::chrono::milliseconds kLinger{1000};
  read_timer_.expires_after(kLinger);
  read_timer_.async_wait([self = shared_from_this()](boost::system::error_code e) {
    if (!e) {
      self->close();
    }
  });
  do_read();
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
    if (ec || self->closed_) {
      return;
    }
    self->server_.counters.timeouts.fetch_add(1, std::memory_order_relaxed);
    spdlog::info("bridge: session {} ({}): no request for {} ms, closing", self->id_, self->peer_,
                 self->server_.opt.read_timeout.count());
    self->close();
  });
}

void Session::do_read() {
  if (closed_ || reading_) {
    return;
  }
  if (queue_.size() >= server_.opt.queue_limit && !lingering_) {
    read_paused_ = true;  // the client is not reading its replies: stop reading its requests
    return;
  }
  reading_ = true;
  socket_.async_read_some(
      asio::buffer(rx_),
      asio::bind_executor(strand_,
                          [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
                            self->on_read(ec, n);
                          }));
}

void Session::on_read(boost::system::error_code ec, std::size_t n) {
  reading_ = false;
  if (ec) {
    fail(ec, "read", id_);
    close();
    return;
  }
  if (lingering_) {  // closing: what the client still sends is read and dropped
    do_read();
    return;
  }
  const std::size_t limit = server_.opt.max_line_bytes;
  std::string_view chunk(rx_.data(), n);
  while (!chunk.empty() && !closed_) {
    const auto nl = chunk.find('\n');
    const std::string_view part = chunk.substr(0, nl);
    if (discarding_) {
      if (nl != std::string_view::npos) {
        discarding_ = false;  // the too-long line has ended; the session goes on
      }
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
    if (nl == std::string_view::npos) {
      break;
    }
    chunk.remove_prefix(nl + 1);
  }
  do_read();
}

void Session::handle_line(std::string_view line) {
  if (close_after_flush_) {
    return;  // the session is ending: later requests get no reply
  }
  if (!line.empty() && line.back() == '\r') {
    line.remove_suffix(1);
  }
  if (line.find_first_not_of(" \t") == std::string_view::npos) {
    return;  // blank lines are keep-alives
  }
  arm_read_timer();
  server_.counters.requests.fetch_add(1, std::memory_order_relaxed);
  ErrorCode code{};
  std::string message;
  Json id;
  auto req = parse_request(line, code, message, id);
  OpResult r;
  if (refusal_) {
    send_reply(make_error(id, refusal_->first, refusal_->second));
    close_after_flush();
    return;
  }
  if (!req) {
    r.reply = make_error(id, code, message);
  } else {
    try {
      r = run_op(*this, *req);
    } catch (const std::exception& e) {  // a bug or bad_alloc must not take the server down
      r.reply = make_error(req->id, ErrorCode::kBadRequest, std::string("internal: ") + e.what());
    }
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
  enqueue(std::make_shared<const std::string>(to_line(reply)));
}

void Session::send_event(std::string_view name, Json body) {
  if (closed_ || close_after_flush_) {
    return;
  }
  if (queue_.size() >= server_.opt.queue_limit) {
    ++dropped_;
    server_.counters.events_dropped.fetch_add(1, std::memory_order_relaxed);
    const auto now = SteadyClock::now();
    if (!stalled_since_) {
      stalled_since_ = now;
    } else if (now - *stalled_since_ > server_.opt.stall_timeout) {
      server_.counters.slow_disconnects.fetch_add(1, std::memory_order_relaxed);
      spdlog::warn(
          "bridge: session {} ({}): not reading for {} ms ({} events dropped); "
          "disconnecting",
          id_, peer_, server_.opt.stall_timeout.count(), dropped_);
      close();
    }
    return;
  }
  server_.counters.events_sent.fetch_add(1, std::memory_order_relaxed);
  enqueue(std::make_shared<const std::string>(to_line(make_event(name, ++seq_, body))));
}

void Session::enqueue(std::shared_ptr<const std::string> msg) {
  queue_.push_back(std::move(msg));
  if (!writing_) {
    do_write();
  }
}

void Session::do_write() {
  if (closed_ || queue_.empty()) {
    return;
  }
  writing_ = true;
  asio::async_write(socket_, asio::buffer(*queue_.front()),
                    asio::bind_executor(strand_, [self = shared_from_this()](
                                                     boost::system::error_code ec, std::size_t n) {
                      self->on_write(ec, n);
                    }));
}

void Session::on_write(boost::system::error_code ec, std::size_t /*n*/) {
  writing_ = false;
  if (ec) {
    fail(ec, "write", id_);
    close();
    return;
  }
  if (!queue_.empty()) {
    queue_.pop_front();
  }
  if (queue_.size() < server_.opt.queue_limit) {
    stalled_since_.reset();
  }
  if (queue_.empty() && close_after_flush_) {
    linger_close();
    return;
  }
  if (read_paused_ && queue_.size() < server_.opt.queue_limit / 2 + 1) {
    read_paused_ = false;
    do_read();
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
