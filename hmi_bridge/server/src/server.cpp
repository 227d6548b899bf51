// The bridge server's shared state: listener, session registry, broadcasts (alarms, progress,
// trace), and start/stop.
#include <spdlog/spdlog.h>

#include <boost/asio/post.hpp>
#include <cmath>
#include <future>
#include <set>

#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge {

namespace {

constexpr auto kProgressPeriod = std::chrono::milliseconds(100);
constexpr auto kTracePeriod = std::chrono::milliseconds(20);
constexpr std::size_t kTraceSamplesPerEvent = 512;
// At most this many trace events per tap per tick (4 × 512 samples / 20 ms: 100 kHz, ten times
// the fastest task). Unbounded, a producer faster than the io thread could serialise (a slow or
// overloaded host) kept trace_tick() from returning: no close, hello or reply ran any more. Past
// the bound the tap's ring overflows and counts it (tap_dropped), as it does for any slow reader.
constexpr int kTraceEventsPerTick = 4;

Json progress_json(const rt::JobProgress& p) {
  return {{"outcome", std::string(rt::outcome_name(p.outcome))},
          {"generation", p.generation},
          {"jobs_started", p.jobs_started},
          {"block", p.block_index},
          {"blocks", p.block_count},
          {"line", p.line}};
}

bool same_progress(const rt::JobProgress& a, const rt::JobProgress& b) {
  return a.outcome == b.outcome && a.generation == b.generation &&
         a.jobs_started == b.jobs_started && a.block_index == b.block_index &&
         a.block_count == b.block_count && a.line == b.line;
}

}  // namespace

const std::vector<std::string>& default_status_vars() {
  static const std::vector<std::string> kVars = {
      "io.x_mm",         "io.y_mm",          "io.z_mm",       "io.depth_mm",
      "io.electrode_mm", "io.gap_voltage_v", "io.ratio_short"};
  return kVars;
}

ServerOptions options_from_config(const rt::BridgeSpec& spec) {
  ServerOptions o;
  o.bind = spec.bind;
  o.port = static_cast<std::uint16_t>(spec.port);
  o.token_file = spec.token_file;
  o.viewer_token_file = spec.viewer_token_file;
  o.max_sessions = spec.max_sessions;
  o.max_line_bytes = spec.max_line_bytes;
  o.read_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(spec.read_timeout);
  o.queue_limit = spec.queue_limit;
  o.stall_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(spec.stall_timeout);
  o.queue_bytes = spec.queue_bytes;
  o.max_pending = spec.max_pending;
  o.hello_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(spec.hello_timeout);
  o.tls_cert = spec.tls_cert;
  o.tls_key = spec.tls_key;
  o.insecure_plaintext = spec.insecure_plaintext;
  o.audit_file = spec.audit_file;
  for (const auto& v : spec.status_vars) {
    o.status_vars.push_back(v.name);
  }
  return o;
}

TokenSet validate_options(const ServerOptions& opt) {
  TokenSet tokens = load_tokens(opt.token_file, opt.viewer_token_file);
  boost::system::error_code ec;
  asio::ip::make_address(opt.bind, ec);
  if (ec) {
    throw BridgeError("bridge.bind '" + opt.bind + "': not an IP address");
  }
  if (opt.tls_cert.empty() != opt.tls_key.empty()) {
    throw BridgeError("bridge.tls: both cert and key are required");
  }
  if (!opt.tls_key.empty()) {
    check_private_file(opt.tls_key, "tls.key");
    make_tls_server_context(opt.tls_cert, opt.tls_key);  // throws naming the file at fault
  }
  if (!is_loopback_address(opt.bind)) {
    if (!tokens.any()) {
      throw BridgeError("bridge.bind " + opt.bind +
                        " is not a loopback address and no token_file is configured; refusing "
                        "to serve the network without authentication");
    }
    if (opt.tls_cert.empty() && !opt.insecure_plaintext) {
      throw BridgeError("bridge.bind " + opt.bind +
                        " is not a loopback address and bridge.tls is not configured; refusing "
                        "to send tokens in clear text (bridge.insecure_plaintext: true to "
                        "allow it anyway)");
    }
  }
  return tokens;
}

Server::Impl::Impl(rt::Runtime& runtime, ServerOptions options)
    : rt(runtime), opt(std::move(options)) {}

void Server::Impl::start() {
  tokens = validate_options(opt);
  const auto address = asio::ip::make_address(opt.bind);
  if (!opt.tls_cert.empty()) {
    tls = make_tls_server_context(opt.tls_cert, opt.tls_key);
  } else if (!is_loopback_address(opt.bind)) {
    spdlog::warn(
        "bridge: INSECURE: serving {} without TLS (bridge.insecure_plaintext): tokens and "
        "commands cross the network in clear text",
        opt.bind);
  }
  audit.open(opt.audit_file);
  boost::system::error_code ec;

  // Status board on the I/O task (the one with the driver), else the first task.
  std::vector<rt::PinRef> pins;
  const bool explicit_vars = !opt.status_vars.empty();
  for (const auto& name : explicit_vars ? opt.status_vars : default_status_vars()) {
    const rt::Variable* v = rt.variables().find(name);
    if (v == nullptr || !v->is_pin()) {
      if (explicit_vars) {
        throw BridgeError("bridge.status_vars: '" + name + "' is not a pin of this config");
      }
      continue;
    }
    if (pins.size() == kMaxStatusVars) {
      throw BridgeError("bridge.status_vars: at most 16 variables");
    }
    pins.push_back(v->pin);
    status_var_names.push_back(name);
  }
  board = std::make_unique<StatusBoard>(rt.machine(), rt.job(), pins);
  for (const rt::Variable& v : rt.variables().all()) {
    constexpr std::string_view kFigure = ".job_time_s";
    if (v.is_pin() && v.name.size() > kFigure.size() && v.name.ends_with(kFigure)) {
      job_block = v.name.substr(0, v.name.size() - kFigure.size());
      break;
    }
  }
  job_log = std::make_unique<JobLog>(rt.retain_path().empty() ? "" : rt.retain_path() + ".jobs.csv",
                                     kJobLogCap);
  electrodes = std::make_unique<ElectrodeTable>(
      rt.retain_path().empty() ? "" : rt.retain_path() + ".electrodes.json");
  condition_edits = std::make_unique<ConditionEdits>(
      rt.retain_path().empty() ? "" : rt.retain_path() + ".conditions.json");
  condition_edits->load_and_apply(rt);
  job_watch.started = rt.job().progress().jobs_started;
  rt::Task* io_task = nullptr;
  for (const auto& t : rt.tasks()) {
    if (t->driver() != nullptr) {
      io_task = t.get();
    }
  }
  if (io_task == nullptr && !rt.tasks().empty()) {
    io_task = rt.tasks().front().get();
  }
  for (const auto& t : rt.tasks()) {
    taps.push_back(std::make_unique<TraceTap>(t->name()));
    tap_names.emplace_back();
    t->add_observer(*taps.back());
  }
  if (io_task != nullptr) {
    io_task->add_observer(*board);
  }

  const tcp::endpoint ep(address, opt.port);
  acceptor.open(ep.protocol(), ec);
  if (!ec) {
    acceptor.set_option(asio::socket_base::reuse_address(true), ec);
    acceptor.bind(ep, ec);
  }
  if (!ec) {
    acceptor.listen(asio::socket_base::max_listen_connections, ec);
  }
  if (ec) {
    throw BridgeError("bridge: cannot listen on " + opt.bind + ":" + std::to_string(opt.port) +
                      ": " + ec.message());
  }
  bound_port = acceptor.local_endpoint().port();

  alarm_link->target = this;
  rt.add_alarm_listener([link = alarm_link](const rt::Alarm& a) {
    std::lock_guard lock(link->mutex);
    if (link->target != nullptr) {
      Impl* self = link->target;
      asio::post(self->ioc, [self, a] { self->on_alarm(a); });
    }
  });
  work.emplace(ioc.get_executor());
  do_accept();
  progress_tick();
  trace_tick();
  thread = std::thread([this] { ioc.run(); });
  started = true;
  spdlog::info("bridge: listening on {}:{} ({}, {}{})", opt.bind, bound_port,
               tls ? "TLS" : "plain TCP",
               tokens.any() ? "token authentication" : "loopback only, no token",
               tokens.viewer_token.empty() ? "" : ", viewer token");
}

void Server::Impl::stop() {
  if (!started.exchange(false)) {
    return;
  }
  stopping.store(true, std::memory_order_release);
  {
    std::lock_guard lock(alarm_link->mutex);
    alarm_link->target = nullptr;
  }
  std::promise<void> done;
  asio::post(ioc, [this, &done] {
    boost::system::error_code ec;
    acceptor.close(ec);
    progress_timer.cancel();
    trace_timer.cancel();
    accept_timer.cancel();
    std::vector<std::shared_ptr<Session>> all = live_sessions();
    for (auto& [id, w] : pending) {
      if (auto s = w.lock()) {
        all.push_back(std::move(s));
      }
    }
    for (auto& s : all) {
      s->close();
    }
    done.set_value();
  });
  done.get_future().wait();
  work.reset();
  // Handlers of closed sockets complete with operation_aborted and re-arm nothing; stop() is
  // only the backstop should one still be pending.
  asio::post(ioc, [this] { ioc.stop(); });
  thread.join();
  spdlog::info("bridge: stopped ({} requests, {} events sent, {} dropped)",
               counters.requests.load(), counters.events_sent.load(),
               counters.events_dropped.load());
}

void Server::Impl::do_accept() {
  acceptor.async_accept(ioc, [this](boost::system::error_code ec, tcp::socket socket) {
    if (ec) {
      on_accept_error(ec);
      return;
    }
    if (accept_backoff.count() > 0) {
      spdlog::info("bridge: accepting again after {} accept errors",
                   counters.accept_errors.load(std::memory_order_relaxed));
      accept_backoff = std::chrono::milliseconds(0);
    }
    if (opt.send_buffer_bytes > 0) {
      socket.set_option(asio::socket_base::send_buffer_size(opt.send_buffer_bytes), ec);
    }
    adopt(tls ? make_tls_transport(std::move(socket), *tls)
              : make_tcp_transport(std::move(socket)));
    do_accept();
  });
}

// Out of descriptors (EMFILE/ENFILE), out of memory, or a network error: accept again later,
// backing off to 1 s, and log once per episode rather than once per failure.
void Server::Impl::on_accept_error(const boost::system::error_code& ec) {
  if (ec == asio::error::operation_aborted || stopping.load(std::memory_order_acquire)) {
    return;
  }
  counters.accept_errors.fetch_add(1, std::memory_order_relaxed);
  if (accept_backoff.count() == 0) {
    spdlog::warn("bridge: accept: {}; backing off", ec.message());
    accept_backoff = std::chrono::milliseconds(10);
  } else {
    accept_backoff = std::min(accept_backoff * 2, std::chrono::milliseconds(1000));
  }
  accept_timer.expires_after(accept_backoff);
  accept_timer.async_wait([this](boost::system::error_code e) {
    if (!e) {
      do_accept();
    }
  });
}

void Server::Impl::adopt(std::unique_ptr<Transport> t) {
  // Pre-authentication connections have a cap of their own. When it is reached the oldest one
  // goes — the oldest of the newcomer's own address when that address holds a quarter of the
  // slots — so a flood of silent sockets never keeps a client that says hello at once out.
  const std::string address = t->peer_address();
  const std::size_t per_peer =
      std::max<std::size_t>(1, static_cast<std::size_t>(opt.max_pending) / 4);
  std::vector<std::shared_ptr<Session>> same_peer;
  std::shared_ptr<Session> oldest;
  for (auto it = pending.begin(); it != pending.end();) {
    auto s = it->second.lock();
    if (!s) {
      it = pending.erase(it);
      continue;
    }
    if (!oldest) {
      oldest = s;
    }
    if (s->peer_address() == address) {
      same_peer.push_back(s);
    }
    ++it;
  }
  std::shared_ptr<Session> evict;
  if (same_peer.size() >= per_peer) {
    evict = same_peer.front();
  } else if (pending.size() >= static_cast<std::size_t>(opt.max_pending)) {
    evict = oldest;
  }
  if (evict) {
    counters.pending_evicted.fetch_add(1, std::memory_order_relaxed);
    spdlog::debug("bridge: session {} ({}): evicted before hello (pending cap)", evict->id(),
                  evict->peer());
    evict->close();
  }
  auto s = std::make_shared<Session>(*this, std::move(t), next_session_id++);
  pending.emplace(s->id(), s);
  counters.sessions_pending.store(pending.size(), std::memory_order_relaxed);
  s->start();
}

bool Server::Impl::admit(Session& s, Role role) {
  std::size_t viewers = 0;
  for (const auto& w : live_sessions()) {
    viewers += w->role() == Role::kViewer ? 1 : 0;
  }
  const auto max = static_cast<std::size_t>(opt.max_sessions);
  const std::size_t reserve = max > 1 ? kOperatorReserve : 0;
  const bool full = sessions.size() >= max || (role == Role::kViewer && viewers >= max - reserve);
  if (full) {
    counters.sessions_refused.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  pending.erase(s.id());
  sessions.emplace(s.id(), s.weak_from_this());
  counters.sessions_pending.store(pending.size(), std::memory_order_relaxed);
  counters.sessions_accepted.fetch_add(1, std::memory_order_relaxed);
  counters.sessions_open.store(sessions.size(), std::memory_order_relaxed);
  return true;
}

void Server::Impl::remove(Session& s) {
  pending.erase(s.id());
  sessions.erase(s.id());
  counters.sessions_pending.store(pending.size(), std::memory_order_relaxed);
  counters.sessions_open.store(sessions.size(), std::memory_order_relaxed);
  if (!s.trace_vars().empty()) {
    retrace();
  }
}

std::vector<std::shared_ptr<Session>> Server::Impl::live_sessions() const {
  std::vector<std::shared_ptr<Session>> out;
  out.reserve(sessions.size());
  for (const auto& [id, w] : sessions) {
    if (auto s = w.lock()) {
      out.push_back(std::move(s));
    }
  }
  return out;
}

void Server::Impl::on_alarm(const rt::Alarm& a) {
  const Json body = ops::alarm_json(a, std::chrono::system_clock::now());
  alarm_history.push_back(body);
  if (std::string& seen = job_watch.recent; seen.size() < 4000) {
    seen += (seen.empty() ? "" : "; ") + std::to_string(static_cast<int>(a.code)) + " " +
            std::string(rt::to_string(a.code)) + " " + a.source + ": " + a.text;
  }
  if (alarm_history.size() > kAlarmHistory) {
    alarm_history.pop_front();
    ++alarms_forgotten;
  }
  for (const auto& s : live_sessions()) {
    if (s->wants(kTopicAlarm)) {
      s->send_event("alarm", body);
    }
  }
}

void Server::Impl::progress_tick() {
  const rt::JobProgress p = rt.job().progress();
  watch_jobs(p);
  watch_measure();
  if (!same_progress(p, last_progress)) {
    last_progress = p;
    const Json body = progress_json(p);
    for (const auto& s : live_sessions()) {
      if (s->wants(kTopicProgress)) {
        s->send_event("progress", body);
      }
    }
  }
  if (const auto now = SteadyClock::now(); now >= next_log_sweep) {
    // A flood of log lines that has stopped is summed up once it has been quiet for a while.
    next_log_sweep = now + std::chrono::seconds(5);
    log_limiter.sweep(
        now, std::chrono::seconds(5), [](const std::string& address, std::uint64_t n) {
          spdlog::info("bridge: {}: {} log lines about its sessions suppressed", address, n);
        });
  }
  progress_timer.expires_after(kProgressPeriod);
  progress_timer.async_wait([this](boost::system::error_code ec) {
    if (!ec) {
      progress_tick();
    }
  });
}

void Server::Impl::retrace() {
  // The union of every session's trace variables, split by owning task.
  std::set<std::string> wanted;
  for (const auto& s : live_sessions()) {
    wanted.insert(s->trace_vars().begin(), s->trace_vars().end());
  }
  const auto& tasks = rt.tasks();
  for (std::size_t i = 0; i < tasks.size() && i < taps.size(); ++i) {
    std::vector<rt::PinRef> pins;
    std::vector<std::string> names;
    for (const auto& name : wanted) {
      const rt::Variable* v = rt.variables().find(name);
      if (v != nullptr && v->is_pin() && v->owner == tasks[i].get() &&
          pins.size() < rt::kMaxTraceVarsPerTask) {
        pins.push_back(v->pin);
        names.push_back(name);
      }
    }
    taps[i]->configure(pins);
    tap_names[i] = std::move(names);
  }
}

void Server::Impl::trace_tick() {
  for (std::size_t i = 0; i < taps.size(); ++i) {
    trace_scratch.clear();
    for (int batch = 0;
         batch < kTraceEventsPerTick && taps[i]->drain(trace_scratch, kTraceSamplesPerEvent) > 0;
         ++batch) {
      const auto& names = tap_names[i];
      for (const auto& s : live_sessions()) {
        if (s->trace_vars().empty()) {
          continue;
        }
        std::vector<std::size_t> cols;
        Json vars = Json::array();
        for (std::size_t c = 0; c < names.size(); ++c) {
          for (const auto& mine : s->trace_vars()) {
            if (mine == names[c]) {
              cols.push_back(c);
              vars.push_back(names[c]);
            }
          }
        }
        if (cols.empty()) {
          continue;
        }
        Json rows = Json::array();
        for (const auto& smp : trace_scratch) {
          Json row = Json::array({rt::to_seconds(smp.release), smp.cycle});
          for (std::size_t c : cols) {
            const double v = c < smp.n ? smp.v[c] : std::nan("");
            row.push_back(std::isfinite(v) ? Json(v) : Json(nullptr));
          }
          rows.push_back(std::move(row));
        }
        s->send_event("trace", {{"task", taps[i]->task_name()},
                                {"vars", std::move(vars)},
                                {"samples", std::move(rows)},
                                {"tap_dropped", taps[i]->dropped()}});
      }
      trace_scratch.clear();
    }
  }
  trace_timer.expires_after(kTracePeriod);
  trace_timer.async_wait([this](boost::system::error_code ec) {
    if (!ec) {
      trace_tick();
    }
  });
}

StatusMessage Server::Impl::status_message() {
  StatusMessage m;
  StatusSnapshot snap;
  if (board && board->read(snap)) {
    m.t_s = rt::to_seconds(snap.release);
    m.cycle = snap.cycle;
    m.state = std::string(rt::to_string(snap.state));
    m.cause = static_cast<int>(snap.cause);
    for (std::uint32_t i = 0; i < snap.n_vars && i < status_var_names.size(); ++i) {
      m.vars.emplace_back(status_var_names[i], snap.vars[i]);
    }
  } else {
    // No cycle has run yet (or no task): the state machine and registry directly.
    snap.state = rt.machine().state();
    snap.job = rt.job().progress();
    m.state = std::string(rt::to_string(snap.state));
    m.cause = static_cast<int>(rt.machine().last_cause());
    for (const auto& name : status_var_names) {
      m.vars.emplace_back(name, rt.variables().read(name).value_or(std::nan("")));
    }
  }
  // Progress is read live (it is atomics already): the snapshot's copy may be a cycle old.
  const rt::JobProgress p = rt.job().progress();
  m.job_outcome = std::string(rt::outcome_name(p.outcome));
  m.job_generation = p.generation;
  m.job_block = p.block_index;
  m.job_blocks = p.block_count;
  m.job_line = p.line;
  m.job_jobs_started = p.jobs_started;
  m.job_slot = p.slot == rt::JobSlot::kMdi ? "mdi" : "main";
  m.job_last = last_job();
  return m;
}

std::optional<LastJob> Server::Impl::last_job() {
  const rt::JobProgress p = rt.job().progress();
  const auto& interrupted = rt.interrupted_job();
  if (interrupted && p.jobs_started == 0) {
    return LastJob{"interrupted",
                   static_cast<std::uint64_t>(interrupted->block_index),
                   static_cast<std::int32_t>(interrupted->line),
                   interrupted->depth_mm,
                   interrupted->touch_z_mm,
                   interrupted->wear_mm};
  }
  if (p.outcome != rt::JobOutcome::kAborted || p.slot != rt::JobSlot::kMain) return std::nullopt;
  LastJob l{"aborted", p.block_index, p.line, std::nullopt, std::nullopt, std::nullopt};
  const rt::RetainSpec& rs = rt.config().retain;
  if (rs.job_depth) l.depth_mm = rt.variables().read(rs.job_depth->name);
  if (rs.job_touch_z) l.touch_z_mm = rt.variables().read(rs.job_touch_z->name);
  if (rs.job_wear) l.wear_mm = rt.variables().read(rs.job_wear->name);
  return l;
}

Server::Server(rt::Runtime& runtime, ServerOptions options)
    : impl_(std::make_unique<Impl>(runtime, std::move(options))) {}

Server::~Server() { stop(); }

void Server::start() { impl_->start(); }
void Server::stop() { impl_->stop(); }
std::uint16_t Server::port() const noexcept { return impl_->bound_port; }

void Server::adopt(std::unique_ptr<Transport> transport) {
  asio::post(impl_->ioc, [impl = impl_.get(), t = std::move(transport)]() mutable {
    impl->adopt(std::move(t));
  });
}

boost::asio::io_context& Server::io_context() noexcept { return impl_->ioc; }

ServerStats Server::stats() const noexcept { return impl_->stats_snapshot(); }

ServerStats Server::Impl::stats_snapshot() const noexcept {
  const Counters& c = counters;
  ServerStats s;
  s.sessions_open = c.sessions_open.load();
  s.sessions_pending = c.sessions_pending.load();
  s.pending_evicted = c.pending_evicted.load();
  s.hello_timeouts = c.hello_timeouts.load();
  s.hello_failures = c.hello_failures.load();
  s.accept_errors = c.accept_errors.load();
  s.queue_bytes_peak = c.queue_bytes_peak.load();
  s.sessions_accepted = c.sessions_accepted.load();
  s.sessions_refused = c.sessions_refused.load();
  s.requests = c.requests.load();
  s.errors = c.errors.load();
  s.events_sent = c.events_sent.load();
  s.events_dropped = c.events_dropped.load();
  s.slow_disconnects = c.slow_disconnects.load();
  s.timeouts = c.timeouts.load();
  s.programs_committed = c.programs_committed.load();
  return s;
}

}  // namespace edm::bridge
