#include "edm/hmi/web_hub.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string_view>

namespace edm::hmi {

namespace {

using bridge::Json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

WebHub::WebHub(boost::asio::io_context& ioc, bridge::Client& client, ConnectionSettings settings)
    : ioc_(ioc),
      client_(client),
      settings_(std::move(settings)),
      job_(client),
      manual_(client),
      shift_(settings_),
      timer_(ioc) {
  bridge_text_ = Json{{"t", "bridge"},
                      {"up", false},
                      {"message", "waiting for edmplc at " + settings_.host + ":" +
                                      std::to_string(settings_.port)}}
                     .dump();
  for (Worker& w : workers_) w.thread = std::thread([this, &w] { worker_loop(w); });
}

WebHub::~WebHub() { stop(); }

void WebHub::stop() {
  if (stopped_) return;
  stopped_ = true;
  {
    std::lock_guard lock(mutex_);
    link_stopping_ = true;
  }
  link_cv_.notify_all();
  if (link_thread_.joinable()) link_thread_.join();
  manual_.stop();     // a held jog is stopped
  shift_.stop_all();  // the queue's job is stopped (the operator's stop), a measurement too
  for (Worker& w : workers_) {
    {
      std::lock_guard lock(w.mutex);
      w.stopping = true;
    }
    w.cv.notify_all();
    if (w.thread.joinable()) w.thread.join();
  }
  timer_.cancel();
  client_.set_event_handler(nullptr);
  client_.set_connection_handler(nullptr);
}

void WebHub::attach(const std::shared_ptr<WebSink>& sink) {
  sinks_.push_back(sink);
  std::lock_guard lock(mutex_);
  ++counters_.browsers;
}

void WebHub::detach(const WebSink* sink) {
  std::erase_if(sinks_, [sink](const std::weak_ptr<WebSink>& w) {
    const auto s = w.lock();
    return !s || s.get() == sink;
  });
}

void WebHub::watch(const std::shared_ptr<WebSink>& sink) {
  std::erase_if(watched_, [](const std::weak_ptr<WebSink>& w) { return w.expired(); });
  watched_.push_back(sink);
}

void WebHub::broadcast_all(const std::string& message) {
  const auto shared = std::make_shared<const std::string>(message);
  std::erase_if(watched_, [](const std::weak_ptr<WebSink>& w) { return w.expired(); });
  for (const auto& w : watched_) {
    if (const auto s = w.lock()) s->send(shared);
  }
}

bool WebHub::ready() const {
  std::lock_guard lock(mutex_);
  return ready_;
}

std::string WebHub::bridge_message() const {
  std::lock_guard lock(mutex_);
  return bridge_text_;
}

void WebHub::broadcast(const std::string& message) {
  const auto shared = std::make_shared<const std::string>(message);
  std::erase_if(sinks_, [](const std::weak_ptr<WebSink>& w) { return w.expired(); });
  for (const auto& w : sinks_) {
    if (const auto s = w.lock()) s->send(shared);
  }
}

bool WebHub::post_work(Lane lane, std::function<void()> work) {
  Worker& w = workers_[static_cast<std::size_t>(lane)];
  {
    std::lock_guard lock(w.mutex);
    if (w.stopping || w.queue.size() >= kWorkQueue) return false;
    w.queue.push_back(std::move(work));
  }
  w.cv.notify_one();
  return true;
}

void WebHub::worker_loop(Worker& w) {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock lock(w.mutex);
      w.cv.wait(lock, [&w] { return w.stopping || !w.queue.empty(); });
      if (w.stopping) return;
      job = std::move(w.queue.front());
      w.queue.pop_front();
    }
    try {
      job();
    } catch (const std::exception& e) {  // never out of a worker: that would end the process
      std::fprintf(stderr, "edmhmi serve: a worker's task failed: %s\n", e.what());
    } catch (...) {
      std::fprintf(stderr, "edmhmi serve: a worker's task failed\n");
    }
  }
}

bridge::Role WebHub::authenticate(const std::string& token, const std::string& peer) {
  bridge::Client probe;
  bridge::ClientOptions o = client_options(settings_);
  o.token = token;
  o.peer = peer;
  o.timeout = std::chrono::seconds(15);  // edmplc delays a hello after wrong ones (up to 10 s)
  const bridge::Role theirs = probe.connect(o);  // throws on a refused token
  probe.close();
  return client_.role() == bridge::Role::kOperator ? theirs : bridge::Role::kViewer;
}

std::string WebHub::welcome(bridge::Role role) const {
  Json series = Json::array();
  std::lock_guard lock(mutex_);
  for (const WebSeries& s : series_) series.push_back({{"key", s.key}, {"var", s.var}});
  const Json w = {{"t", "welcome"},
                  {"role", std::string(bridge::to_string(role))},
                  {"machine", job_.machine_info()},
                  {"caps", caps_},
                  {"series", series},
                  {"frame_hz", kFrameHz},
                  {"job", job_.snapshot()},
                  {"alarms", alarms_json_locked()},
                  {"history", Json(history_)},
                  {"status", last_status_},
                  {"manual", manual_.manual_json()},
                  {"offsets", manual_.offsets_json()},
                  {"queue", shift_.snapshot()},
                  {"bridge", bridge_up_}};
  return w.dump(-1, ' ', false, Json::error_handler_t::replace);
}

Json WebHub::alarms_json_locked() const {
  Json a = Json::array();
  for (const Json& j : alarms_) a.push_back(j);
  return a;
}

void WebHub::acknowledge_alarms(std::uint64_t seq) {
  std::string msg;
  {
    std::lock_guard lock(mutex_);
    for (Json& a : alarms_) {
      if (a.value("seq", std::uint64_t{0}) <= seq) a["acked"] = true;
    }
    msg = page_text(Json{{"t", "alarms"}, {"alarms", alarms_json_locked()}});
  }
  broadcast(msg);
}

void WebHub::broadcast_job() {
  broadcast(Json{{"t", "job"}, {"job", job_.snapshot()}}.dump(-1, ' ', false,
                                                              Json::error_handler_t::replace));
}

WebHub::Counters WebHub::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

void WebHub::count_drop() {
  std::lock_guard lock(mutex_);
  ++counters_.frames_dropped;
}

void WebHub::count_slow_disconnect() {
  std::lock_guard lock(mutex_);
  ++counters_.slow_disconnects;
}

void WebHub::count_reply_overflow() {
  std::lock_guard lock(mutex_);
  ++counters_.reply_overflows;
}

void WebHub::count_login_failure() {
  std::lock_guard lock(mutex_);
  ++counters_.login_failures;
}

void WebHub::on_event(const Json& ev) {
  const std::string kind = ev.value("event", std::string());
  if (kind == "trace") return on_trace(ev);
  if (kind == "status") {
    bridge::StatusMessage s;
    std::string error;
    if (bridge::from_json(ev, s, error)) {
      job_.on_status(s);
      manual_.on_status_time(s.t_s);
    }
    Json st = ev;
    st.erase("event");
    st.erase("seq");
    std::lock_guard lock(mutex_);
    last_status_ = std::move(st);
    status_fresh_ = true;
  } else if (kind == "alarm") {
    job_.on_alarm(ev);
    Json a = ev;
    a.erase("event");
    std::lock_guard lock(mutex_);
    a["seq"] = ++alarm_seq_;
    a["acked"] = false;
    alarms_.push_back(a);
    if (alarms_.size() > kMaxAlarms) alarms_.pop_front();
    new_alarms_.push_back(std::move(a));
  }
}

void WebHub::on_trace(const Json& ev) {
  if (!ev.contains("vars") || !ev["vars"].is_array() || !ev.contains("samples")) return;
  const Json& vars = ev["vars"];
  std::lock_guard lock(mutex_);
  // Column of each series in this event's rows (+2: t_s and cycle come first).
  std::vector<int> column(series_.size(), -1);
  for (std::size_t i = 0; i < series_.size(); ++i) {
    for (std::size_t c = 0; c < vars.size(); ++c) {
      if (vars[c].is_string() && vars[c].get_ref<const std::string&>() == series_[i].var) {
        column[i] = static_cast<int>(c) + 2;
      }
    }
  }
  for (const Json& sample : ev["samples"]) {
    if (!sample.is_array() || sample.empty() || !sample[0].is_number()) continue;
    for (std::size_t i = 0; i < series_.size(); ++i) {
      const int c = column[i];
      if (c >= 0 && static_cast<std::size_t>(c) < sample.size()) {
        row_[i] = sample[c].is_number() ? sample[c].get<double>() : kNaN;
      }
    }
    const double t = sample[0].get<double>();
    if (t < last_row_t_) last_row_t_ = -1.0;  // edmplc restarted: its clock began again
    if (last_row_t_ >= 0.0 && t < last_row_t_ + kRowPeriodS) continue;
    last_row_t_ = t;
    Json row = Json::array({t});
    for (double v : row_) {
      if (std::isfinite(v)) {
        row.push_back(v);
      } else {
        row.push_back(nullptr);
      }
    }
    rows_.push_back(std::move(row));
    if (rows_.size() > 4 * kMaxRowsPerFrame * kFrameHz) rows_.erase(rows_.begin());
  }
}

void WebHub::arm_timer() {
  timer_.expires_after(std::chrono::milliseconds(1000 / kFrameHz));
  timer_.async_wait([this](boost::system::error_code ec) {
    if (ec) return;
    on_timer();
    arm_timer();
  });
}

void WebHub::on_timer() {
  Json frame = {{"t", "frame"}};
  bool any = false;
  {
    std::lock_guard lock(mutex_);
    if (status_fresh_) {
      frame["status"] = last_status_;
      status_fresh_ = false;
      any = true;
    }
    if (!rows_.empty()) {
      Json rows = Json::array();
      if (rows_.size() <= kMaxRowsPerFrame) {
        for (Json& r : rows_) rows.push_back(std::move(r));
      } else {  // evenly spaced, the newest always kept
        for (std::size_t k = 0; k < kMaxRowsPerFrame; ++k) {
          const std::size_t i =
              rows_.size() - 1 - (kMaxRowsPerFrame - 1 - k) * (rows_.size() / kMaxRowsPerFrame);
          rows.push_back(std::move(rows_[i]));
        }
      }
      rows_.clear();
      for (const Json& r : rows) history_.push_back(r);
      while (history_.size() > kHistoryRows) history_.pop_front();
      frame["rows"] = std::move(rows);
      any = true;
    }
    if (!new_alarms_.empty()) {
      frame["alarms"] = std::move(new_alarms_);
      new_alarms_.clear();
      any = true;
    }
    if (bridge_changed_) {
      bridge_changed_ = false;
      any = true;
    }
    WebManual::Changes changes = manual_.take_changes();
    if (!changes.manual.is_null()) {
      frame["manual"] = std::move(changes.manual);
      any = true;
    }
    if (!changes.offsets.is_null()) {
      frame["offsets"] = std::move(changes.offsets);
      any = true;
    }
    if (Json q = shift_.take_changes(); !q.is_null()) {
      frame["queue"] = std::move(q);
      any = true;
    }
    frame["bridge"] = bridge_up_;
    frame["dropped"] = counters_.frames_dropped;
    if (any) ++counters_.frames;
  }
  if (any) broadcast(frame.dump(-1, ' ', false, Json::error_handler_t::replace));
}

}  // namespace edm::hmi
