#include "edm/sparkplug/fleet.hpp"

#include <mosquitto.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

namespace edm::sparkplug {

namespace {

std::string fixed(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// For the terminal table: control characters (a metric's text may carry escape sequences that
// rewrite the screen) shown as '?'. Display only; logs quote and escape instead.
std::string printable(std::string s) {
  for (char& c : s) {
    const auto b = static_cast<unsigned char>(c);
    if (b < 0x20 || b == 0x7F) c = '?';
  }
  return s;
}

nlohmann::json to_json(const Value& v) {
  if (std::holds_alternative<std::monostate>(v)) return nullptr;
  if (const auto* b = std::get_if<bool>(&v)) return *b;
  if (const auto* i = std::get_if<std::int64_t>(&v)) return *i;
  if (const auto* u = std::get_if<std::uint64_t>(&v)) return *u;
  if (const auto* d = std::get_if<double>(&v))
    return std::isfinite(*d) ? nlohmann::json(*d) : nullptr;
  return std::get<std::string>(v);
}

}  // namespace

std::string FleetMachine::text(std::string_view name) const {
  const auto it = metrics.find(std::string(name));
  return it == metrics.end() ? "-" : to_text(it->second);
}

std::string FleetMachine::job() const {
  const std::string outcome = text("job/outcome");
  if (outcome == "-" || outcome == "none") return "-";
  const auto block = metrics.find("job/block");
  const auto blocks = metrics.find("job/blocks");
  std::string s = outcome;
  if (block != metrics.end() && blocks != metrics.end()) {
    const double b = as_double(block->second).value_or(0.0);
    const double n = as_double(blocks->second).value_or(0.0);
    s += " " + fixed(b, 0) + "/" + fixed(n, 0);
    if (n > 0.0) s += " (" + fixed(100.0 * b / n, 0) + " %)";
  }
  const std::string line = text("job/line");
  if (outcome == "running" && line != "-") s += " line " + line;
  return s;
}

void FleetTable::apply(std::map<std::string, Value>& into, const Payload& from, bool clear) {
  if (clear) {
    kept_ -= into.size();
    into.clear();
  }
  for (const Metric& m : from.metrics) {
    if (m.historical || m.name.empty()) continue;
    Value v = m.value;
    if (auto* s = std::get_if<std::string>(&v); s && s->size() > limits_.max_string_bytes) {
      s->resize(limits_.max_string_bytes);
    }
    const auto it = into.find(m.name);
    if (it != into.end()) {
      it->second = std::move(v);
    } else if (m.name.size() <= limits_.max_name_bytes && kept_ < limits_.max_metrics) {
      into.emplace(m.name, std::move(v));
      ++kept_;
    } else {
      ++ignored_metrics_;
    }
  }
}

void FleetTable::on_message(std::string_view topic, std::string_view payload,
                            std::uint64_t now_ms) {
  const auto t = parse_topic(topic);
  if (!t || t->type == MessageType::kState || t->type == MessageType::kNCmd ||
      t->type == MessageType::kDCmd) {
    return;
  }
  if (std::max({t->group.size(), t->node.size(), t->device.size()}) > limits_.max_id_bytes) {
    ++ignored_messages_;
    return;
  }
  std::optional<Payload> p;
  if (screen_payload(payload, limits_.payload).verdict == Screen::kOk) p = decode(payload);
  const auto key = std::make_pair(t->group, t->node);
  auto node_it = nodes_.find(key);
  if (!p || (node_it == nodes_.end() && nodes_.size() >= limits_.max_nodes)) {
    ++ignored_messages_;
    return;
  }
  if (node_it == nodes_.end()) node_it = nodes_.emplace(key, Node{}).first;
  Node& n = node_it->second;
  if (!t->device.empty() && n.devices.count(t->device) == 0 &&
      n.devices.size() >= limits_.max_devices_per_node) {
    ++ignored_messages_;
    return;
  }
  n.last_seen_ms = now_ms;
  if (t->type == MessageType::kNDeath) {
    const Metric* bd = p->find(kBdSeq);
    const auto bdseq = bd ? as_double(bd->value) : std::nullopt;
    // A will from an older session (bdSeq of another birth) says nothing about this one.
    if (!n.born || (bdseq && static_cast<std::uint64_t>(*bdseq) == n.bdseq)) {
      n.online = false;
      for (auto& [id, d] : n.devices) d.online = false;
    }
    return;
  }
  if (p->seq) {
    if (t->type == MessageType::kNBirth) {
      n.last_seq = *p->seq;
    } else if (n.last_seq) {
      if (*p->seq != (*n.last_seq + 1) % 256) ++n.seq_gaps;
      n.last_seq = *p->seq;
    }
  }
  switch (t->type) {
    case MessageType::kNBirth: {
      n.online = n.born = true;
      if (const Metric* bd = p->find(kBdSeq)) {
        n.bdseq = static_cast<std::uint64_t>(as_double(bd->value).value_or(0.0));
      }
      apply(n.metrics, *p, true);
      asked_.erase(key);
      break;
    }
    case MessageType::kNData:
      apply(n.metrics, *p, false);
      if (!n.born && asked_.count(key) == 0) rebirth_.insert(key);
      break;
    case MessageType::kDBirth: {
      FleetMachine& d = n.devices[t->device];
      d.online = d.born = true;
      apply(d.metrics, *p, true);
      break;
    }
    case MessageType::kDData: {
      FleetMachine& d = n.devices[t->device];
      apply(d.metrics, *p, false);
      if (!d.born && asked_.count(key) == 0) rebirth_.insert(key);
      break;
    }
    case MessageType::kDDeath: n.devices[t->device].online = false; break;
    default: break;
  }
}

std::vector<std::pair<std::string, std::string>> FleetTable::take_rebirth_requests() {
  std::vector<std::pair<std::string, std::string>> out(rebirth_.begin(), rebirth_.end());
  for (const auto& k : rebirth_) asked_.insert(k);
  rebirth_.clear();
  return out;
}

std::vector<FleetMachine> FleetTable::machines() const {
  std::vector<FleetMachine> out;
  for (const auto& entry : nodes_) {
    const auto& key = entry.first;
    const auto& n = entry.second;  // not a structured binding: clang 14 cannot capture those
    const auto fill = [&](FleetMachine m) {
      const auto& k = key;
      m.group = k.first;
      m.node = k.second;
      m.bdseq = n.bdseq;
      m.seq_gaps = n.seq_gaps;
      m.last_seen_ms = n.last_seen_ms;
      m.node_metrics = n.metrics;
      return m;
    };
    if (n.devices.empty()) {
      FleetMachine m;
      m.online = n.online;
      m.born = n.born;
      m.metrics = n.metrics;
      out.push_back(fill(std::move(m)));
    }
    for (const auto& [id, d] : n.devices) {
      FleetMachine m = d;
      m.device = id;
      m.online = d.online && n.online;
      out.push_back(fill(std::move(m)));
    }
  }
  return out;
}

std::string render_text(const std::vector<FleetMachine>& machines, std::uint64_t now_ms) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-32s %-7s %-10s %-28s %-24s %s\n", "MACHINE", "ONLINE",
                "STATE", "JOB", "ALARMS", "SEEN");
  out += line;
  for (const FleetMachine& m : machines) {
    std::string name = m.group + "/" + m.node + (m.device.empty() ? "" : "/" + m.device);
    std::string alarms = m.text("alarms/active");
    if (alarms.empty() || alarms == "-") alarms = m.text("alarms/count") == "0" ? "none" : alarms;
    const double age_s =
        now_ms >= m.last_seen_ms ? static_cast<double>(now_ms - m.last_seen_ms) / 1000.0 : 0.0;
    std::snprintf(line, sizeof line, "%-32s %-7s %-10s %-28s %-24s %s s ago\n",
                  printable(name).c_str(), m.online ? "yes" : (m.born ? "no" : "?"),
                  printable(m.text("state")).c_str(), printable(m.job()).c_str(),
                  printable(alarms).c_str(), fixed(age_s, 1).c_str());
    out += line;
  }
  if (machines.empty()) out += "(no machine heard on the broker)\n";
  return out;
}

std::string render_json(const std::vector<FleetMachine>& machines, std::uint64_t now_ms) {
  nlohmann::json arr = nlohmann::json::array();
  for (const FleetMachine& m : machines) {
    nlohmann::json metrics = nlohmann::json::object();
    for (const auto& [k, v] : m.metrics) metrics[k] = to_json(v);
    nlohmann::json node = nlohmann::json::object();
    for (const auto& [k, v] : m.node_metrics) node[k] = to_json(v);
    arr.push_back(
        {{"group", m.group},
         {"node", m.node},
         {"device", m.device},
         {"online", m.online},
         {"born", m.born},
         {"bdseq", m.bdseq},
         {"seq_gaps", m.seq_gaps},
         {"state", m.text("state")},
         {"job", m.job()},
         {"alarms", m.text("alarms/active")},
         {"seen_s_ago",
          now_ms >= m.last_seen_ms ? static_cast<double>(now_ms - m.last_seen_ms) / 1000.0 : 0.0},
         {"metrics", std::move(metrics)},
         {"node_metrics", std::move(node)}});
  }
  // Metric strings are not checked UTF-8 (proto2): invalid bytes become U+FFFD, never a throw.
  return arr.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

FleetWatcher::FleetWatcher(FleetOptions options) : opt_(std::move(options)) {}

FleetWatcher::~FleetWatcher() {
  if (mosq_ != nullptr) {
    mosquitto_disconnect(mosq_);
    mosquitto_loop_stop(mosq_, true);
    mosquitto_destroy(mosq_);
  }
}

void FleetWatcher::on_connect_cb(mosquitto* m, void* self_ptr, int rc) {
  auto* self = static_cast<FleetWatcher*>(self_ptr);
  if (rc == 0) {
    const std::string sub = std::string(kNamespace) + "/" +
                            (self->opt_.group.empty() ? std::string("+") : self->opt_.group) + "/#";
    mosquitto_subscribe(m, nullptr, sub.c_str(), 0);
  }
  std::lock_guard lock(self->mu_);
  self->connected_ = rc == 0;
  self->connack_ = rc;
}

void FleetWatcher::on_message_cb(mosquitto* /*m*/, void* self_ptr, const mosquitto_message* msg) {
  auto* self = static_cast<FleetWatcher*>(self_ptr);
  const std::string_view payload(static_cast<const char*>(msg->payload),
                                 static_cast<std::size_t>(msg->payloadlen));
  std::lock_guard lock(self->mu_);
  self->table_.on_message(msg->topic, payload, now_ms());
}

void FleetWatcher::start() {
  static const int init = mosquitto_lib_init();
  (void)init;
  const std::string id = opt_.client_id.empty() ? "edmhmi-fleet-" + std::to_string(::getpid()) +
                                                      "-" + std::to_string(now_ms() % 100000)
                                                : opt_.client_id;
  mosq_ = mosquitto_new(id.c_str(), true, this);
  if (mosq_ == nullptr) throw EdgeNodeError("cannot create a libmosquitto client");
  mosquitto_int_option(mosq_, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
  mosquitto_connect_callback_set(mosq_, &FleetWatcher::on_connect_cb);
  mosquitto_message_callback_set(mosq_, &FleetWatcher::on_message_cb);
  if (!opt_.username.empty()) {
    mosquitto_username_pw_set(mosq_, opt_.username.c_str(),
                              opt_.password.empty() ? nullptr : opt_.password.c_str());
  }
  if (opt_.tls) {
    const auto n = [](const std::string& s) { return s.empty() ? nullptr : s.c_str(); };
    const int rc = mosquitto_tls_set(mosq_, n(opt_.tls->ca_file), nullptr, n(opt_.tls->cert_file),
                                     n(opt_.tls->key_file), nullptr);
    if (rc != MOSQ_ERR_SUCCESS) throw EdgeNodeError(std::string("tls: ") + mosquitto_strerror(rc));
    mosquitto_tls_insecure_set(mosq_, !opt_.tls->verify_hostname);
  }
  const int rc = mosquitto_connect(mosq_, opt_.host.c_str(), opt_.port, 10);
  if (rc != MOSQ_ERR_SUCCESS) {
    throw EdgeNodeError("cannot connect to the broker " + opt_.host + ":" +
                        std::to_string(opt_.port) + ": " +
                        (rc == MOSQ_ERR_ERRNO ? std::string(std::strerror(errno))
                                              : std::string(mosquitto_strerror(rc))));
  }
  mosquitto_loop_start(mosq_);
}

void FleetWatcher::poll() {
  if (!opt_.ask_rebirth) return;
  std::vector<std::pair<std::string, std::string>> asks;
  {
    std::lock_guard lock(mu_);
    asks = table_.take_rebirth_requests();
  }
  for (const auto& [group, node] : asks) {
    Payload p;
    p.timestamp = now_ms();
    Metric m;
    m.name = std::string(kRebirth);
    m.type = DataType::kBoolean;
    m.value = true;
    m.timestamp = p.timestamp;
    p.metrics.push_back(std::move(m));
    const std::string bytes = encode(p);
    const std::string topic = Topic{group, MessageType::kNCmd, node, ""}.str();
    mosquitto_publish(mosq_, nullptr, topic.c_str(), static_cast<int>(bytes.size()), bytes.data(),
                      0, false);
  }
}

std::vector<FleetMachine> FleetWatcher::machines() const {
  std::lock_guard lock(mu_);
  return table_.machines();
}

bool FleetWatcher::connected() const {
  std::lock_guard lock(mu_);
  return connected_;
}

}  // namespace edm::sparkplug
