#include "edm/telemetry/mqtt_config.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "edm/machining/located_yaml.hpp"
#include "edm/runtime/config_section.hpp"
#include "edm/runtime/diagnostics.hpp"
#include "edm/runtime/time.hpp"

namespace edm::telemetry {

namespace {

namespace y = machining::yaml;

// The edge of what one device's DBIRTH should carry; past it, use more nodes.
constexpr std::size_t kMaxMetrics = 64;

std::string resolve(const std::string& file, const std::string& config_path) {
  const std::filesystem::path p(file);
  if (p.is_absolute()) return file;
  return (std::filesystem::path(config_path).parent_path() / p).string();
}

class SectionParser {
 public:
  SectionParser(const std::string& path, rt::DiagnosticSink& sink, const rt::VariableRegistry& vars)
      : path_(path), r_(path, sink), vars_(vars) {}

  std::optional<std::chrono::milliseconds> duration(const y::Value& v, double min_s, double max_s) {
    auto s = r_.string(v);
    if (!s) return std::nullopt;
    const auto d = rt::parse_duration(*s);
    if (!d.value) {
      r_.error(v, d.error);
      return std::nullopt;
    }
    const double sec = rt::to_seconds(*d.value);
    if (sec < min_s || sec > max_s) {
      r_.error(v, "must be between " +
                      rt::format_duration(std::chrono::duration_cast<rt::Duration>(
                          std::chrono::duration<double>(min_s))) +
                      " and " +
                      rt::format_duration(std::chrono::duration_cast<rt::Duration>(
                          std::chrono::duration<double>(max_s))));
      return std::nullopt;
    }
    return std::chrono::duration_cast<std::chrono::milliseconds>(*d.value);
  }

  std::optional<double> deadband(const y::Value& v) {
    auto d = r_.real(v);
    if (d && !(*d >= 0.0)) {
      r_.error(v, "a deadband is >= 0 (0: every change is reported)");
      return std::nullopt;
    }
    return d;
  }

  std::optional<std::string> id(const y::Value& v) {
    auto s = r_.string(v);
    if (s && !sparkplug::valid_id(*s)) {
      r_.error(v, "a Sparkplug id may not contain '/', '+' or '#'");
      return std::nullopt;
    }
    return s;
  }

  std::optional<std::string> file(const y::Value& v, const char* what) {
    auto s = r_.string(v);
    if (!s) return std::nullopt;
    const std::string p = resolve(*s, path_);
    if (!std::filesystem::is_regular_file(p)) {
      r_.error(v, std::string("cannot read the ") + what + " '" + p + "'");
      return std::nullopt;
    }
    return p;
  }

  void parse(const y::Value& v, const std::string& machine_name, MqttConfig& c) {
    c.loc = v.loc;
    auto m = r_.map(v, {"broker", "group", "node", "device", "client_id", "interval", "heartbeat",
                        "keepalive", "deadband", "metrics", "store_forward", "username",
                        "password_file", "tls", "commands", "limits"});
    if (!m) return;
    if (const y::Field* f = r_.require(*m, "broker")) broker(f->value, c);
    if (const y::Field* f = r_.require(*m, "group")) c.group = id(f->value).value_or("");
    if (const y::Field* f = r_.require(*m, "node")) c.node = id(f->value).value_or("");
    c.device = sparkplug::valid_id(machine_name) ? machine_name : "machine";
    if (const y::Field* f = m->find("device")) c.device = id(f->value).value_or(c.device);
    if (const y::Field* f = m->find("client_id")) c.client_id = r_.string(f->value).value_or("");
    if (const y::Field* f = m->find("interval")) {
      c.interval = duration(f->value, 0.01, 60.0).value_or(c.interval);
    }
    if (const y::Field* f = m->find("heartbeat")) {
      c.heartbeat = duration(f->value, 0.0, 3600.0).value_or(c.heartbeat);
    }
    if (const y::Field* f = m->find("keepalive")) {
      if (auto d = duration(f->value, 5.0, 3600.0)) {
        c.keepalive = std::chrono::duration_cast<std::chrono::seconds>(*d);
      }
    }
    if (const y::Field* f = m->find("deadband")) c.deadband = deadband(f->value).value_or(0.0);
    if (const y::Field* f = m->find("metrics")) metrics(f->value, c);
    if (const y::Field* f = m->find("store_forward")) {
      if (auto n = r_.integer(f->value, 0, 1000000)) c.store_forward = static_cast<std::size_t>(*n);
    }
    if (const y::Field* f = m->find("username")) c.username = r_.string(f->value).value_or("");
    if (const y::Field* f = m->find("password_file")) {
      if (auto p = file(f->value, "password file")) {
        std::ifstream in(*p);
        std::getline(in, c.password);
        while (!c.password.empty() && (c.password.back() == '\r' || c.password.back() == ' ')) {
          c.password.pop_back();
        }
        if (c.password.empty()) r_.error(f->value, "the password file is empty");
      }
      if (c.username.empty()) r_.error(f->value, "password_file needs a username");
    }
    if (const y::Field* f = m->find("tls")) tls(f->value, c);
    if (const y::Field* f = m->find("commands")) commands(f->value, c);
    if (const y::Field* f = m->find("limits")) limits(f->value, c);
  }

 private:
  void broker(const y::Value& v, MqttConfig& c) {
    auto s = r_.string(v);
    if (!s) return;
    const auto colon = s->rfind(':');
    if (colon == std::string::npos || colon == 0) {
      r_.error(v, "expected HOST:PORT, e.g. 127.0.0.1:1883");
      return;
    }
    c.host = s->substr(0, colon);
    const std::string port = s->substr(colon + 1);
    int p = 0;
    bool ok = !port.empty() && port.size() <= 5;
    for (char ch : port) {
      ok = ok && ch >= '0' && ch <= '9';
      if (ok) p = p * 10 + (ch - '0');
    }
    if (!ok || p < 1 || p > 65535) {
      r_.error(v, "the port must be 1..65535, not '" + port + "'");
      return;
    }
    c.port = p;
  }

  void metrics(const y::Value& v, MqttConfig& c) {
    auto items = r_.list(v);
    if (!items) return;
    for (const y::Value& item : *items) {
      MetricSpec ms;
      ms.loc = item.loc;
      ms.deadband = -1.0;  // the section's default, filled in below
      if (item.node.IsMap()) {
        auto m = r_.map(item, {"var", "name", "deadband"});
        if (!m) continue;
        if (const y::Field* f = r_.require(*m, "var")) {
          ms.var = r_.string(f->value).value_or("");
          ms.loc = f->value.loc;
        }
        if (const y::Field* f = m->find("name")) ms.name = r_.string(f->value).value_or("");
        if (const y::Field* f = m->find("deadband")) ms.deadband = deadband(f->value).value_or(0.0);
      } else {
        ms.var = r_.string(item).value_or("");
      }
      if (ms.var.empty()) continue;
      const rt::Variable* var = vars_.find(ms.var);
      if (var == nullptr) {
        r_.error(ms.loc, item.path, "unknown variable '" + ms.var + "' (edmplc --list-vars)");
        continue;
      }
      if (!var->is_pin() && var->param_type == rt::ParamType::kString) {
        r_.error(ms.loc, item.path, "'" + ms.var + "' is a string parameter: not published");
        continue;
      }
      if (ms.name.empty()) ms.name = ms.var;
      const bool dup = std::any_of(c.metrics.begin(), c.metrics.end(),
                                   [&](const MetricSpec& o) { return o.name == ms.name; });
      if (dup) {
        r_.error(ms.loc, item.path, "metric '" + ms.name + "' is listed twice");
        continue;
      }
      if (c.metrics.size() == kMaxMetrics) {
        r_.error(ms.loc, item.path, "at most 64 metrics per machine");
        continue;
      }
      c.metrics.push_back(std::move(ms));
    }
  }

  void tls(const y::Value& v, MqttConfig& c) {
    auto m = r_.map(v, {"ca_file", "cert_file", "key_file", "verify_hostname"});
    if (!m) return;
    sparkplug::TlsOptions t;
    if (const y::Field* f = r_.require(*m, "ca_file"))
      t.ca_file = file(f->value, "CA file").value_or("");
    if (const y::Field* f = m->find("cert_file"))
      t.cert_file = file(f->value, "certificate").value_or("");
    if (const y::Field* f = m->find("key_file")) t.key_file = file(f->value, "key").value_or("");
    if (t.cert_file.empty() != t.key_file.empty()) {
      r_.error(v, "cert_file and key_file go together");
    }
    if (const y::Field* f = m->find("verify_hostname")) {
      if (auto s = r_.choice(f->value, {"true", "false"})) t.verify_hostname = *s == "true";
    }
    c.tls = t;
  }

  void limits(const y::Value& v, MqttConfig& c) {
    auto m = r_.map(v, {"max_payload_bytes", "max_metrics"});
    if (!m) return;
    if (const y::Field* f = m->find("max_payload_bytes")) {
      if (auto n = r_.integer(f->value, 1024, 16 << 20)) {
        c.limits.max_payload_bytes = static_cast<std::size_t>(*n);
      }
    }
    if (const y::Field* f = m->find("max_metrics")) {
      if (auto n = r_.integer(f->value, 1, 65536))
        c.limits.max_metrics = static_cast<std::size_t>(*n);
    }
  }

  void commands(const y::Value& v, MqttConfig& c) {
    auto m = r_.map(v, {"enabled", "writable"});
    if (!m) return;
    if (const y::Field* f = m->find("enabled")) {
      if (auto s = r_.choice(f->value, {"true", "false"})) c.commands_enabled = *s == "true";
    }
    if (const y::Field* f = m->find("writable")) {
      auto items = r_.list(f->value);
      if (!items) return;
      for (const y::Value& item : *items) {
        auto name = r_.string(item);
        if (!name) continue;
        const rt::Variable* var = vars_.find(*name);
        if (var == nullptr) {
          r_.error(item, "unknown variable '" + *name + "'");
        } else if (var->is_pin()) {
          r_.error(item, "'" + *name + "' is a pin: only parameters are writable by command");
        } else if (var->load_time_only) {
          r_.error(item,
                   "'" + *name + "' is a load-time parameter: it cannot change while running");
        } else if (var->param_type == rt::ParamType::kString) {
          r_.error(item, "'" + *name + "' is a string parameter: not writable by command");
        } else {
          c.writable.push_back(*name);
        }
      }
    }
    if (c.commands_enabled && c.writable.empty() && m->find("writable") == nullptr) {
      r_.error(v, "commands.enabled needs a writable: list (the parameters commands may write)");
    }
  }

  std::string path_;
  y::Reader r_;
  const rt::VariableRegistry& vars_;
};

}  // namespace

std::optional<MqttConfig> parse_mqtt_text(const std::string& text, const std::string& path,
                                          const std::string& machine_name,
                                          const rt::VariableRegistry& vars) {
  const std::optional<y::Value> section = rt::config_section(text, path, "mqtt");
  if (!section) return std::nullopt;
  rt::DiagnosticSink sink;
  SectionParser p(path, sink, vars);
  MqttConfig c;
  p.parse(*section, machine_name, c);
  sink.throw_if_any();
  for (MetricSpec& m : c.metrics) {
    if (m.deadband < 0.0) m.deadband = c.deadband;
  }
  return c;
}

std::optional<MqttConfig> load_mqtt_config(const rt::Config& cfg,
                                           const rt::VariableRegistry& vars) {
  if (cfg.mqtt_loc.line == 0) return std::nullopt;
  return parse_mqtt_text(rt::read_config_text(cfg), cfg.path, cfg.machine.name, vars);
}

}  // namespace edm::telemetry
