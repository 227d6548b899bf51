// Request and reply: numbered requests waiting on promises, replies matched by id (an id-less
// reply to the oldest waiting request), events to the handler, and the public request calls.
#include <boost/asio/post.hpp>

#include "client_impl.hpp"

namespace edm::bridge {

namespace {

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

Reply transport_error(std::string message) {
  Reply r;
  r.message = std::move(message);
  return r;
}

void Client::Impl::handle_line(const std::string& line) {
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

Reply Client::Impl::wait(const std::shared_ptr<Promise>& p,
                         std::optional<std::chrono::milliseconds> timeout,
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

Reply Client::Impl::send(const std::string& line, std::optional<std::int64_t> id,
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

Reply Client::Impl::request(std::string_view op, const Json& params,
                            std::optional<std::chrono::milliseconds> timeout) {
  std::int64_t id = 0;
  {
    std::lock_guard lock(mu);
    id = next_id++;
  }
  return send(to_line(make_request(id, op, params)), id, timeout);
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

// What reconnect replays: remembered once the server accepted it, forgotten before the stop.
Reply Client::subscribe(const std::vector<std::string>& topics, int rate_hz) {
  Reply r = request("subscribe", {{"topics", topics}, {"rate_hz", rate_hz}});
  if (r) {
    impl_->locked([&] {
      impl_->sub_topics = topics;
      impl_->sub_rate = rate_hz;
    });
  }
  return r;
}

Reply Client::unsubscribe() {
  impl_->locked([&] { impl_->sub_topics.clear(); });
  return request("unsubscribe");
}

Reply Client::trace_start(const std::vector<std::string>& vars) {
  Reply r = request("trace.start", {{"vars", vars}});
  if (r) {
    impl_->locked([&] { impl_->trace_vars = vars; });
  }
  return r;
}

Reply Client::trace_stop() {
  impl_->locked([&] { impl_->trace_vars.clear(); });
  return request("trace.stop");
}

}  // namespace edm::bridge
