#include "edm/sparkplug/edge_node.hpp"

#include <mosquitto.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string_view>
#include <utility>

namespace edm::sparkplug {

namespace {

constexpr std::string_view kQueued = "Store Forward/queued";
constexpr std::string_view kDropped = "Store Forward/dropped";
constexpr std::string_view kAccepted = "Commands/accepted";
constexpr std::string_view kRefused = "Commands/refused";
constexpr std::string_view kCmdDropped = "Commands/dropped";
constexpr std::string_view kOutOfRange = "Commands/out_of_range";
constexpr std::string_view kUptime = "Node Info/uptime_s";

void lib_init() {
  static const int rc = mosquitto_lib_init();  // once per process, thread-safe static init
  (void)rc;
}

bool same(const Value& a, const Value& b, double deadband) {
  const auto da = as_double(a);
  const auto db = as_double(b);
  if (da && db && !std::holds_alternative<bool>(a)) {
    if (std::isnan(*da) || std::isnan(*db)) return std::isnan(*da) && std::isnan(*db);
    return deadband > 0.0 ? std::fabs(*da - *db) <= deadband : *da == *db;
  }
  return a == b;
}

// libmosquitto's messages end with a full stop; ours go on after them.
std::string clause(const char* text) {
  std::string s = text != nullptr ? text : "";
  while (!s.empty() && (s.back() == '.' || s.back() == ' ')) s.pop_back();
  return s;
}

Metric metric(std::string_view name, DataType type, Value v, std::uint64_t t_ms) {
  Metric m;
  m.name = std::string(name);
  m.type = type;
  m.value = std::move(v);
  m.timestamp = t_ms;
  return m;
}

}  // namespace

EdgeNode::EdgeNode(EdgeNodeOptions options, CommandSink on_command)
    : opt_(std::move(options)), on_command_(std::move(on_command)) {
  for (const auto* id : {&opt_.group, &opt_.node, &opt_.device}) {
    if (!valid_id(*id)) {
      throw EdgeNodeError(
          "mqtt: group, node and device ids must be non-empty without '/', '+', '#'");
    }
  }
  if (opt_.client_id.empty()) opt_.client_id = opt_.group + ":" + opt_.node;
  if (opt_.tls) {
    for (const auto* f : {&opt_.tls->ca_file, &opt_.tls->cert_file, &opt_.tls->key_file}) {
      if (!f->empty() && !std::filesystem::is_regular_file(*f)) {
        throw EdgeNodeError("mqtt.tls: cannot read '" + *f + "'");
      }
    }
  }
  ncmd_ = Topic{opt_.group, MessageType::kNCmd, opt_.node, ""};
  dcmd_ = Topic{opt_.group, MessageType::kDCmd, opt_.node, opt_.device};
  reported_.resize(opt_.device_metrics.size());
}

EdgeNode::~EdgeNode() {
  stop();
  if (mosq_ != nullptr) mosquitto_destroy(mosq_);
}

void EdgeNode::log(const std::string& line) const {
  if (opt_.log) opt_.log(line);
}

void EdgeNode::warn(const std::string& line) const {
  if (opt_.warn) {
    opt_.warn(line);
  } else {
    log(line);
  }
}

std::string EdgeNode::broker() const { return opt_.host + ":" + std::to_string(opt_.port); }

void EdgeNode::connect_failed(const std::string& why) {
  {
    std::lock_guard lock(mu_);
    // libmosquitto retries every few seconds: say each reason once, not every 8 s for days.
    if (failures_.size() >= 16 ||
        std::find(failures_.begin(), failures_.end(), why) != failures_.end())
      return;
    failures_.push_back(why);
  }
  warn(why);
}

void EdgeNode::set_will_locked() {
  Payload death;
  death.timestamp = now_ms();
  death.metrics.push_back(metric(kBdSeq, DataType::kUInt64, bdseq_, death.timestamp));
  const std::string bytes = encode(death);
  const std::string topic = Topic{opt_.group, MessageType::kNDeath, opt_.node, ""}.str();
  mosquitto_will_set(mosq_, topic.c_str(), static_cast<int>(bytes.size()), bytes.data(), 1, false);
}

void EdgeNode::start() {
  if (started_) return;
  lib_init();
  mosq_ = mosquitto_new(opt_.client_id.c_str(), true, this);
  if (mosq_ == nullptr) throw EdgeNodeError("mqtt: cannot create a libmosquitto client");
  mosquitto_int_option(mosq_, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
  // Small messages: no Nagle delay on the node's side (docs/benchmarks.md, the 40 ms tail).
  mosquitto_int_option(mosq_, MOSQ_OPT_TCP_NODELAY, 1);
  mosquitto_connect_callback_set(mosq_, &EdgeNode::on_connect_cb);
  mosquitto_disconnect_callback_set(mosq_, &EdgeNode::on_disconnect_cb);
  mosquitto_message_callback_set(mosq_, &EdgeNode::on_message_cb);
  mosquitto_log_callback_set(mosq_, &EdgeNode::on_log_cb);
  mosquitto_reconnect_delay_set(mosq_, static_cast<unsigned>(opt_.reconnect_min_s),
                                static_cast<unsigned>(opt_.reconnect_max_s), true);
  if (!opt_.username.empty() &&
      mosquitto_username_pw_set(mosq_, opt_.username.c_str(),
                                opt_.password.empty() ? nullptr : opt_.password.c_str()) !=
          MOSQ_ERR_SUCCESS) {
    throw EdgeNodeError("mqtt: username/password refused by libmosquitto");
  }
  if (opt_.tls) {
    const auto opt_or_null = [](const std::string& s) { return s.empty() ? nullptr : s.c_str(); };
    const int rc = mosquitto_tls_set(mosq_, opt_or_null(opt_.tls->ca_file), nullptr,
                                     opt_or_null(opt_.tls->cert_file),
                                     opt_or_null(opt_.tls->key_file), nullptr);
    if (rc != MOSQ_ERR_SUCCESS) {
      throw EdgeNodeError(std::string("mqtt.tls: ") + mosquitto_strerror(rc));
    }
    mosquitto_tls_insecure_set(mosq_, !opt_.tls->verify_hostname);
  }
  {
    std::lock_guard lock(mu_);
    set_will_locked();
  }
  started_at_ = std::chrono::steady_clock::now();
  // A broker that is not up yet is not an error: the network thread keeps retrying. Nor is a
  // handshake that failed at once (MOSQ_ERR_TLS): on_log_cb told why, tick() tries again.
  const int rc = mosquitto_connect_async(mosq_, opt_.host.c_str(), opt_.port, opt_.keepalive_s);
  if (rc != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_ERRNO && rc != MOSQ_ERR_TLS) {
    throw EdgeNodeError(std::string("mqtt: connect to ") + opt_.host + ": " +
                        mosquitto_strerror(rc));
  }
  if (rc == MOSQ_ERR_ERRNO) log("mqtt: broker " + opt_.host + " not reachable yet; retrying");
  if (mosquitto_loop_start(mosq_) != MOSQ_ERR_SUCCESS) {
    throw EdgeNodeError("mqtt: cannot start libmosquitto's network thread");
  }
  started_ = true;
}

void EdgeNode::on_connect_cb(mosquitto* m, void* self_ptr, int rc) {
  auto* self = static_cast<EdgeNode*>(self_ptr);
  if (rc != 0) {
    {
      std::lock_guard lock(self->mu_);
      self->conn_refused_ = true;  // the disconnect that follows says nothing more
    }
    // MQTT 3.1.1 CONNACK 4 "bad user name or password", 5 "not authorised" (mosquitto's answer
    // to a wrong password, an unknown user and to no credentials with allow_anonymous false).
    const bool credentials = rc == 4 || rc == 5;
    self->connect_failed("mqtt: the broker " + self->broker() +
                         " refused the connection: " + clause(mosquitto_connack_string(rc)) +
                         (credentials ? (self->opt_.username.empty()
                                             ? " (no mqtt.username and mqtt.password_file set)"
                                             : " (check mqtt.username '" + self->opt_.username +
                                                   "' and its mqtt.password_file)")
                                      : std::string()) +
                         "; retrying");
    return;
  }
  // Commands first, so none sent right after the births is missed (Sparkplug: subscribe before
  // NBIRTH).
  const std::string n = self->ncmd_.str();
  const std::string d = self->dcmd_.str();
  mosquitto_subscribe(m, nullptr, n.c_str(), 1);
  mosquitto_subscribe(m, nullptr, d.c_str(), 1);
  {
    std::lock_guard lock(self->mu_);
    self->connected_ = true;
    self->need_birth_ = true;
    self->will_used_ = true;
    self->tls_failed_ = false;
    self->failures_.clear();
    ++self->connects_;
  }
  self->log("mqtt: connected to the broker " + self->broker() +
            (self->opt_.tls ? " over TLS" : ""));
}

void EdgeNode::on_disconnect_cb(mosquitto* /*m*/, void* self_ptr, int rc) {
  auto* self = static_cast<EdgeNode*>(self_ptr);
  bool was = false;
  bool said = false;  // a refusal or a TLS error, already told
  {
    std::lock_guard lock(self->mu_);
    was = self->connected_;
    self->connected_ = false;
    said = std::exchange(self->conn_refused_, false) || self->tls_failed_;
    if (self->will_used_) {
      // The next CONNECT carries a new will: Sparkplug's bdSeq counts sessions, 0..255.
      self->bdseq_ = (self->bdseq_ + 1) % 256;
      self->will_used_ = false;
      self->set_will_locked();
    }
  }
  if (rc == 0) return;  // our own DISCONNECT
  if (was) {
    self->log("mqtt: connection to the broker lost; storing data until it is back");
  } else if (!said) {
    // E.g. plain MQTT to a TLS listener: the broker closes the connection before any CONNACK.
    self->connect_failed("mqtt: cannot connect to the broker " + self->broker() + ": " +
                         clause(mosquitto_strerror(rc)) + "; retrying");
  }
}

void EdgeNode::on_log_cb(mosquitto* /*m*/, void* self_ptr, int level, const char* line) {
  if (level != MOSQ_LOG_ERR || line == nullptr) return;
  auto* self = static_cast<EdgeNode*>(self_ptr);
  const std::string_view text(line);
  constexpr std::string_view kOpenSsl = "OpenSSL Error[";          // "OpenSSL Error[0]: error:…"
  if (text.starts_with("Error: host name verification failed")) {  // followed by OpenSSL's line
    self->connect_failed("mqtt: TLS with the broker " + self->broker() +
                         " failed: its certificate does not name " + self->opt_.host +
                         " (mqtt.tls.verify_hostname: true); retrying");
    return;
  }
  if (!text.starts_with(kOpenSsl)) {
    self->connect_failed("mqtt: libmosquitto: " + std::string(text));
    return;
  }
  // A failed handshake (or any TLS error): libmosquitto's network thread ends after it; tick()
  // starts it again.
  {
    std::lock_guard lock(self->mu_);
    self->tls_failed_ = true;
  }
  const auto colon = text.find("]: ");
  const std::string what(colon == std::string_view::npos ? text : text.substr(colon + 3));
  std::string hint;
  if (what.find("certificate verify failed") != std::string::npos) {
    hint = " (the broker's certificate is not signed by mqtt.tls.ca_file";
    if (self->opt_.tls && self->opt_.tls->verify_hostname) {
      hint += ", or does not name " + self->opt_.host;
    }
    hint += ")";
  }
  self->connect_failed("mqtt: TLS with the broker " + self->broker() + " failed: " + what + hint +
                       "; retrying");
}

void EdgeNode::restart_network_thread() {
  // libmosquitto's thread has returned (a TLS error is fatal to its loop) or is about to:
  // join it (cancelling is safe either way: stop() does the same), connect again, start it.
  // A handshake failing again right here is MOSQ_ERR_TLS, already told by on_log_cb, and
  // scheduled again by it.
  mosquitto_loop_stop(mosq_, true);
  const int rc = mosquitto_connect_async(mosq_, opt_.host.c_str(), opt_.port, opt_.keepalive_s);
  if (rc != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_ERRNO && rc != MOSQ_ERR_TLS) {
    connect_failed("mqtt: cannot connect to the broker " + broker() + ": " +
                   clause(mosquitto_strerror(rc)) + "; retrying");
  }
  if (mosquitto_loop_start(mosq_) != MOSQ_ERR_SUCCESS) {
    warn("mqtt: cannot start libmosquitto's network thread again; telemetry is off");
    started_ = false;
  }
}

void EdgeNode::on_message_cb(mosquitto* /*m*/, void* self_ptr, const mosquitto_message* msg) {
  auto* self = static_cast<EdgeNode*>(self_ptr);
  if (!self->on_command_) return;
  // Network thread: the sink looks at the size and copies what it bounds; it never decodes.
  const std::string_view payload(
      static_cast<const char*>(msg->payload),
      msg->payloadlen > 0 ? static_cast<std::size_t>(msg->payloadlen) : 0);
  self->on_command_(msg->topic != nullptr ? msg->topic : "", payload, msg->retain);
}

bool EdgeNode::publish(const Topic& topic, Payload& p) {
  if (topic.type != MessageType::kNDeath) {
    p.seq = seq_;
    seq_ = (seq_ + 1) % 256;
  }
  const std::string bytes = encode(p);
  const std::string t = topic.str();
  const int rc = mosquitto_publish(mosq_, nullptr, t.c_str(), static_cast<int>(bytes.size()),
                                   bytes.data(), 0, false);
  if (rc != MOSQ_ERR_SUCCESS) return false;
  published_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

std::vector<Metric> EdgeNode::node_counters(std::uint64_t t_ms) const {
  const auto up = std::chrono::duration_cast<std::chrono::seconds>(
      std::chrono::steady_clock::now() - started_at_);
  return {metric(kQueued, DataType::kUInt64, static_cast<std::uint64_t>(store_.size()), t_ms),
          metric(kDropped, DataType::kUInt64, dropped_.load(), t_ms),
          metric(kAccepted, DataType::kUInt64, cmd_accepted_.load(), t_ms),
          metric(kRefused, DataType::kUInt64, cmd_refused_.load(), t_ms),
          metric(kCmdDropped, DataType::kUInt64, cmd_dropped_.load(), t_ms),
          metric(kOutOfRange, DataType::kUInt64, cmd_out_of_range_.load(), t_ms),
          metric(kUptime, DataType::kUInt64, static_cast<std::uint64_t>(up.count()), t_ms)};
}

void EdgeNode::publish_births(std::span<const Value> values, std::uint64_t t_ms) {
  std::uint64_t bdseq = 0;
  {
    std::lock_guard lock(mu_);
    bdseq = bdseq_;
  }
  seq_ = 0;  // NBIRTH is always seq 0
  Payload nb;
  nb.timestamp = now_ms();
  nb.metrics.push_back(metric(kBdSeq, DataType::kUInt64, bdseq, nb.timestamp));
  nb.metrics.push_back(metric(kRebirth, DataType::kBoolean, false, nb.timestamp));
  for (auto& m : node_counters(nb.timestamp)) nb.metrics.push_back(std::move(m));
  Payload db;
  db.timestamp = nb.timestamp;
  for (std::size_t i = 0; i < opt_.device_metrics.size() && i < values.size(); ++i) {
    db.metrics.push_back(
        metric(opt_.device_metrics[i].name, opt_.device_metrics[i].type, values[i], t_ms));
  }
  if (!publish(Topic{opt_.group, MessageType::kNBirth, opt_.node, ""}, nb) ||
      !publish(Topic{opt_.group, MessageType::kDBirth, opt_.node, opt_.device}, db)) {
    return;  // lost the connection meanwhile: the next connect births again
  }
  birthed_ = true;
  births_.fetch_add(1, std::memory_order_relaxed);
  reported_.assign(values.begin(), values.end());
  have_reported_ = true;
  last_counters_.clear();
  last_ndata_ = std::chrono::steady_clock::now();
}

void EdgeNode::replay_store() {
  const Topic ddata{opt_.group, MessageType::kDData, opt_.node, opt_.device};
  while (!store_.empty()) {
    Payload p = std::move(store_.front());
    store_.pop_front();
    for (auto& m : p.metrics) m.historical = true;
    if (!publish(ddata, p)) {
      store_.push_front(std::move(p));  // connection gone again: keep it for the next one
      break;
    }
    replayed_.fetch_add(1, std::memory_order_relaxed);
  }
  queued_.store(store_.size(), std::memory_order_relaxed);
}

void EdgeNode::store(Payload p) {
  if (opt_.store_capacity == 0) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (store_.size() >= opt_.store_capacity) {
    store_.pop_front();
    dropped_.fetch_add(1, std::memory_order_relaxed);
  }
  store_.push_back(std::move(p));
  stored_.fetch_add(1, std::memory_order_relaxed);
  queued_.store(store_.size(), std::memory_order_relaxed);
}

void EdgeNode::publish_node_data(std::uint64_t t_ms, bool force) {
  std::vector<Metric> counters = node_counters(t_ms);
  std::vector<Value> now;
  for (std::size_t i = 0; i + 1 < counters.size(); ++i) now.push_back(counters[i].value);
  const bool due = opt_.heartbeat.count() > 0 &&
                   std::chrono::steady_clock::now() - last_ndata_ >= opt_.heartbeat;
  if (!force && !due && now == last_counters_) return;
  Payload nd;
  nd.timestamp = now_ms();
  nd.metrics = std::move(counters);
  if (publish(Topic{opt_.group, MessageType::kNData, opt_.node, ""}, nd)) {
    last_counters_ = std::move(now);
    last_ndata_ = std::chrono::steady_clock::now();
  }
}

void EdgeNode::tick(std::span<const Value> values, std::uint64_t t_ms) {
  if (!started_) return;
  bool connected = false;
  bool birth = false;
  bool tls_failed = false;
  {
    std::lock_guard lock(mu_);
    connected = connected_;
    birth = need_birth_ && connected_;
    need_birth_ = false;
    tls_failed = tls_failed_ && !connected_;
    tls_failed_ = tls_failed;
  }
  if (connected) restart_delay_s_ = 0;
  if (tls_failed) {
    const auto now = std::chrono::steady_clock::now();
    if (restart_at_ == std::chrono::steady_clock::time_point{}) {
      const int lo = std::max(opt_.reconnect_min_s, 1);
      restart_delay_s_ = std::clamp(restart_delay_s_ * 2, lo, std::max(opt_.reconnect_max_s, lo));
      restart_at_ = now + std::chrono::seconds(restart_delay_s_);
    } else if (now >= restart_at_) {
      restart_at_ = {};
      {
        std::lock_guard lock(mu_);
        tls_failed_ = false;
      }
      restart_network_thread();
      if (!started_) return;
    }
  }
  if (!connected) birthed_ = false;
  if (birth) {
    publish_births(values, t_ms);
    if (birthed_) replay_store();
  }
  if (!have_reported_) {  // the first values are the baseline (a broker down from the start)
    reported_.assign(values.begin(), values.end());
    have_reported_ = true;
  }
  if (birth) {
    if (birthed_) publish_node_data(t_ms, true);
    return;
  }
  Payload dd;
  dd.timestamp = t_ms;
  for (std::size_t i = 0; i < opt_.device_metrics.size() && i < values.size(); ++i) {
    const MetricDef& def = opt_.device_metrics[i];
    if (!same(values[i], reported_[i], def.deadband)) {
      dd.metrics.push_back(metric(def.name, def.type, values[i], t_ms));
      reported_[i] = values[i];
    }
  }
  if (!dd.metrics.empty()) {
    if (!(connected && birthed_) ||
        !publish(Topic{opt_.group, MessageType::kDData, opt_.node, opt_.device}, dd)) {
      store(std::move(dd));
    }
  }
  if (connected && birthed_) publish_node_data(t_ms, false);
}

void EdgeNode::stop() {
  if (!started_) return;
  started_ = false;
  bool connected = false;
  {
    std::lock_guard lock(mu_);
    connected = connected_;
  }
  if (connected && birthed_) {
    Payload dd;
    dd.timestamp = now_ms();
    publish(Topic{opt_.group, MessageType::kDDeath, opt_.node, opt_.device}, dd);
    Payload nd;
    nd.timestamp = dd.timestamp;
    {
      std::lock_guard lock(mu_);
      nd.metrics.push_back(metric(kBdSeq, DataType::kUInt64, bdseq_, nd.timestamp));
    }
    publish(Topic{opt_.group, MessageType::kNDeath, opt_.node, ""}, nd);
  }
  mosquitto_disconnect(mosq_);
  // Connected: the thread sends what is queued and the DISCONNECT, then ends. Away: it may be
  // sleeping between reconnects, so it is cancelled (libmosquitto supports that).
  mosquitto_loop_stop(mosq_, !connected);
}

void EdgeNode::request_rebirth() {
  std::lock_guard lock(mu_);
  need_birth_ = connected_;
}

void EdgeNode::set_command_counters(const CommandCounters& c) noexcept {
  cmd_accepted_.store(c.accepted, std::memory_order_relaxed);
  cmd_refused_.store(c.refused, std::memory_order_relaxed);
  cmd_dropped_.store(c.dropped, std::memory_order_relaxed);
  cmd_out_of_range_.store(c.out_of_range, std::memory_order_relaxed);
}

EdgeNodeStats EdgeNode::stats() const {
  EdgeNodeStats s;
  {
    std::lock_guard lock(mu_);
    s.connected = connected_;
    s.connects = connects_;
    s.bdseq = bdseq_;
  }
  s.births = births_.load();
  s.published = published_.load();
  s.stored = stored_.load();
  s.queued = queued_.load();
  s.dropped = dropped_.load();
  s.replayed = replayed_.load();
  s.commands_accepted = cmd_accepted_.load();
  s.commands_refused = cmd_refused_.load();
  s.commands_dropped = cmd_dropped_.load();
  s.commands_out_of_range = cmd_out_of_range_.load();
  return s;
}

}  // namespace edm::sparkplug
