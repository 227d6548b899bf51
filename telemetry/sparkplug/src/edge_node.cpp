#include "edm/sparkplug/edge_node.hpp"

#include <mosquitto.h>

#include <cmath>
#include <filesystem>
#include <utility>

namespace edm::sparkplug {

namespace {

constexpr std::string_view kQueued = "Store Forward/queued";
constexpr std::string_view kDropped = "Store Forward/dropped";
constexpr std::string_view kAccepted = "Commands/accepted";
constexpr std::string_view kRefused = "Commands/refused";
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

Metric metric(std::string_view name, DataType type, Value v, std::uint64_t t_ms) {
  Metric m;
  m.name = std::string(name);
  m.type = type;
  m.value = std::move(v);
  m.timestamp = t_ms;
  return m;
}

}  // namespace

EdgeNode::EdgeNode(EdgeNodeOptions options, CommandHandler on_command)
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
  // A broker that is not up yet is not an error: the network thread keeps retrying.
  const int rc = mosquitto_connect_async(mosq_, opt_.host.c_str(), opt_.port, opt_.keepalive_s);
  if (rc != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_ERRNO) {
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
    self->log(std::string("mqtt: the broker refused the connection: ") +
              mosquitto_connack_string(rc));
    return;
  }
  // Commands first, so none sent right after the births is missed (Sparkplug: subscribe before
  // NBIRTH).
  const std::string n = self->ncmd_.str();
  const std::string d = self->dcmd_.str();
  mosquitto_subscribe(m, nullptr, n.c_str(), 1);
  mosquitto_subscribe(m, nullptr, d.c_str(), 1);
  std::lock_guard lock(self->mu_);
  self->connected_ = true;
  self->need_birth_ = true;
  self->will_used_ = true;
  ++self->connects_;
}

void EdgeNode::on_disconnect_cb(mosquitto* /*m*/, void* self_ptr, int rc) {
  auto* self = static_cast<EdgeNode*>(self_ptr);
  std::lock_guard lock(self->mu_);
  const bool was = self->connected_;
  self->connected_ = false;
  if (self->will_used_) {
    // The next CONNECT carries a new will: Sparkplug's bdSeq counts sessions, 0..255.
    self->bdseq_ = (self->bdseq_ + 1) % 256;
    self->will_used_ = false;
    self->set_will_locked();
  }
  if (was && rc != 0)
    self->log("mqtt: connection to the broker lost; storing data until it is back");
}

void EdgeNode::on_message_cb(mosquitto* /*m*/, void* self_ptr, const mosquitto_message* msg) {
  auto* self = static_cast<EdgeNode*>(self_ptr);
  std::lock_guard lock(self->mu_);
  if (self->inbox_.size() >= 256) return;  // a command flood is dropped here, not queued forever
  self->inbox_.emplace_back(msg->topic, std::string(static_cast<const char*>(msg->payload),
                                                    static_cast<std::size_t>(msg->payloadlen)));
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
          metric(kAccepted, DataType::kUInt64, accepted_.load(), t_ms),
          metric(kRefused, DataType::kUInt64, refused_.load(), t_ms),
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

void EdgeNode::handle_commands() {
  std::deque<std::pair<std::string, std::string>> inbox;
  {
    std::lock_guard lock(mu_);
    inbox.swap(inbox_);
  }
  for (const auto& [topic, bytes] : inbox) {
    const auto t = parse_topic(topic);
    const auto p = decode(bytes);
    if (!t || !p) {
      refused_.fetch_add(1, std::memory_order_relaxed);
      log("mqtt: refused a command on " + topic + ": not a Sparkplug B payload");
      continue;
    }
    for (const Metric& m : p->metrics) {
      if (t->type == MessageType::kNCmd && m.name == kRebirth) {
        if (as_double(m.value).value_or(0.0) != 0.0) {
          std::lock_guard lock(mu_);
          need_birth_ = connected_;
        }
        continue;
      }
      std::string why = "commands are off (mqtt.commands.enabled)";
      const bool ok = on_command_ && on_command_(t->type, m, why);
      (ok ? accepted_ : refused_).fetch_add(1, std::memory_order_relaxed);
      log(std::string("mqtt: ") + std::string(to_string(t->type)) + " " + m.name + " = " +
          to_text(m.value) + (ok ? ": accepted" : ": refused: " + why));
    }
  }
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
  handle_commands();
  bool connected = false;
  bool birth = false;
  {
    std::lock_guard lock(mu_);
    connected = connected_;
    birth = need_birth_ && connected_;
    need_birth_ = false;
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
  s.commands_accepted = accepted_.load();
  s.commands_refused = refused_.load();
  return s;
}

}  // namespace edm::sparkplug
