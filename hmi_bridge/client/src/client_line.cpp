// Line transport of the bridge client: JSON Lines framed by asio::async_read_until over a
// dynamic buffer bounded to the longest accepted line, one write in flight, keep-alive pings.
#include <boost/asio/post.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/write.hpp>
#include <limits>
#include <utility>

#include "client_impl.hpp"

namespace edm::bridge {

void Client::Impl::start_read(const std::shared_ptr<Conn>& c) {
  // One byte more than the longest line, for its '\n': a longer line ends in not_found.
  const std::size_t max = opt.max_line_bytes < std::numeric_limits<std::size_t>::max()
                              ? opt.max_line_bytes + 1
                              : opt.max_line_bytes;
  auto buffer = asio::dynamic_buffer(c->rx, max);
  auto h = [self = shared_from_this(), c](boost::system::error_code ec, std::size_t n) {
    self->on_line(c, ec, n);
  };
  if (c->tls) {
    asio::async_read_until(*c->tls, buffer, '\n', std::move(h));
  } else {
    asio::async_read_until(c->socket, buffer, '\n', std::move(h));
  }
}

void Client::Impl::on_line(const std::shared_ptr<Conn>& c, boost::system::error_code ec,
                           std::size_t n) {
  if (c->dead) {
    return;
  }
  if (ec == asio::error::not_found) {
    // Longer than max_line_bytes: dropped, and so is the rest of it up to its '\n'.
    c->rx.clear();
    c->discarding = true;
    start_read(c);
    return;
  }
  if (ec) {
    lose(c, ec == asio::error::eof ? "connection closed by the server" : ec.message());
    return;
  }
  std::string line = c->rx.substr(0, n - 1);  // without its '\n'
  c->rx.erase(0, n);
  if (!std::exchange(c->discarding, false)) {
    handle_line(line);
  }
  start_read(c);
}

void Client::Impl::write(const std::shared_ptr<Conn>& c, std::string line) {
  if (c->dead) {
    return;
  }
  c->wq.push_back(std::move(line));
  c->last_write = std::chrono::steady_clock::now();
  if (!c->writing) {
    do_write(c);
  }
}

void Client::Impl::do_write(const std::shared_ptr<Conn>& c) {
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

void Client::Impl::arm_keepalive(const std::shared_ptr<Conn>& c) {
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

void Client::Impl::lose(const std::shared_ptr<Conn>& c, const std::string& why) {
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

void Client::Impl::drop_connection() {
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

}  // namespace edm::bridge
