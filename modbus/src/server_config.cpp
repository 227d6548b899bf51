// The `modbus_server:` section (docs/modbus.md), read from the config file like `mqtt:`: the
// runtime's parser only notes where it is.

#include "edm/modbus/server_config.hpp"

#include <map>
#include <sstream>

#include "edm/machining/located_yaml.hpp"
#include "edm/runtime/config_section.hpp"
#include "edm/runtime/diagnostics.hpp"
#include "edm/runtime/time.hpp"

namespace edm::modbus {

namespace {

namespace y = machining::yaml;

constexpr std::size_t kMaxEntries = 4096;  // MapRegisters indexes entries with int16
constexpr std::int64_t kMaxClients = 64;
constexpr std::chrono::milliseconds kMinFrameTimeout{10};
constexpr std::chrono::milliseconds kMaxFrameTimeout{60000};
constexpr std::chrono::milliseconds kMaxIdleTimeout{24 * 3600 * 1000};

class SectionParser {
 public:
  SectionParser(const std::string& path, rt::DiagnosticSink& sink, const rt::VariableRegistry& vars)
      : r_(path, sink), vars_(vars) {}

  void parse(const y::Value& v, ServerConfig& c) {
    c.loc = v.loc;
    auto m = r_.map(v, {"bind", "port", "max_clients", "max_clients_per_address", "frame_timeout",
                        "idle_timeout", "log_burst", "log_per_s", "map"});
    if (!m) {
      return;
    }
    if (const y::Field* f = m->find("bind")) {
      if (auto s = r_.string(f->value)) {
        c.bind = *s;
      }
    }
    if (const y::Field* f = m->find("port")) {
      if (auto p = r_.integer(f->value, 0, 65535)) {
        c.port = static_cast<int>(*p);
      }
    }
    if (const y::Field* f = m->find("max_clients")) {
      if (auto p = r_.integer(f->value, 1, kMaxClients)) {
        c.max_clients = static_cast<int>(*p);
      }
    }
    if (const y::Field* f = m->find("max_clients_per_address")) {
      if (auto p = r_.integer(f->value, 1, kMaxClients)) {
        if (*p > c.max_clients) {
          r_.error(f->value, "must be at most max_clients (" + std::to_string(c.max_clients) + ")");
        } else {
          c.max_clients_per_address = static_cast<int>(*p);
        }
      }
    }
    duration(*m, "frame_timeout", kMinFrameTimeout, kMaxFrameTimeout, c.frame_timeout);
    duration(*m, "idle_timeout", kMinFrameTimeout, kMaxIdleTimeout, c.idle_timeout);
    if (const y::Field* f = m->find("idle_timeout");
        f != nullptr && c.idle_timeout < c.frame_timeout) {
      r_.error(f->value,
               "must be at least frame_timeout (" + rt::format_duration(c.frame_timeout) + ")");
    }
    if (const y::Field* f = m->find("log_burst")) {
      if (auto p = r_.integer(f->value, 1, 1000)) {
        c.log_burst = static_cast<int>(*p);
      }
    }
    if (const y::Field* f = m->find("log_per_s")) {
      if (auto x = r_.real(f->value)) {
        if (!(*x > 0.0 && *x <= 1000.0)) {
          r_.error(f->value, "must be a number in (0, 1000] (log lines a second per address)");
        } else {
          c.log_per_s = *x;
        }
      }
    }
    const y::Field* f = r_.require(*m, "map");
    auto items = f != nullptr ? r_.list(f->value) : std::nullopt;
    if (!items) {
      return;
    }
    if (items->empty() || items->size() > kMaxEntries) {
      r_.error(f->value, "must list 1 to " + std::to_string(kMaxEntries) + " values");
      return;
    }
    for (const y::Value& item : *items) {
      ServerEntry e;
      if (entry(item, e)) {
        c.map.push_back(std::move(e));
      }
    }
  }

 private:
  // A duration key in [min, max], with its unit ("250ms", "1s").
  void duration(const y::MapView& m, const char* key, std::chrono::milliseconds min,
                std::chrono::milliseconds max, std::chrono::milliseconds& out) {
    const y::Field* f = m.find(key);
    if (f == nullptr) {
      return;
    }
    auto s = r_.string(f->value);
    if (!s) {
      return;
    }
    const auto d = rt::parse_duration(*s);
    if (!d.value) {
      r_.error(f->value, d.error);
      return;
    }
    const auto v = std::chrono::duration_cast<std::chrono::milliseconds>(*d.value);
    if (*d.value < min || *d.value > max) {
      r_.error(f->value,
               "must be from " + rt::format_duration(min) + " to " + rt::format_duration(max));
      return;
    }
    out = v;
  }

  bool entry(const y::Value& v, ServerEntry& e) {
    e.loc = v.loc;
    auto m =
        r_.map(v, {"table", "address", "var", "type", "word_order", "scale", "offset", "writable"});
    if (!m) {
      return false;
    }
    bool ok = true;
    if (const y::Field* f = r_.require(*m, "table")) {
      if (auto s = r_.choice(f->value,
                             {"coil", "discrete_input", "input_register", "holding_register"})) {
        e.table = *s == "coil"             ? Table::kCoil
                  : *s == "discrete_input" ? Table::kDiscreteInput
                  : *s == "input_register" ? Table::kInputRegister
                                           : Table::kHoldingRegister;
      } else {
        ok = false;
      }
    } else {
      ok = false;
    }
    if (const y::Field* f = r_.require(*m, "address")) {
      if (auto a = r_.integer(f->value, 0, 65535)) {
        e.address = static_cast<std::uint16_t>(*a);
      } else {
        ok = false;
      }
    } else {
      ok = false;
    }
    const rt::Variable* var = nullptr;
    if (const y::Field* f = r_.require(*m, "var")) {
      if (auto s = r_.string(f->value)) {
        var = vars_.find(*s);
        if (var == nullptr) {
          r_.error(f->value,
                   "unknown variable " + y::quote(*s) + " (edmplc --list-vars lists them)");
          ok = false;
        } else if (var->kind == rt::VarKind::kParam && var->param_type == rt::ParamType::kString) {
          r_.error(f->value, "'" + *s + "' is a STRING parameter: not a number");
          ok = false;
        } else {
          e.var = *s;
          e.unit = var->unit;
        }
      }
    } else {
      ok = false;
    }
    const bool bit = is_bit_table(e.table);
    e.enc.type = bit ? ValueType::kBool : ValueType::kUint16;
    for (const char* key : {"type", "word_order", "scale", "offset"}) {
      if (const y::Field* f = m->find(key)) {
        if (bit) {
          r_.error(f->key_loc, v.path, std::string(key) + " does not apply to a bit");
          ok = false;
          continue;
        }
        if (!r_.scalar(f->value, "a scalar")) {
          ok = false;
          continue;
        }
        std::string error;
        const rt::PinMapField pf{key, f->value.node.Scalar(), y::Reader::is_quoted(f->value.node)};
        if (!parse_encoding_field(pf, e.enc, error)) {
          r_.error(f->value, error);
          ok = false;
        }
      }
    }
    if (const y::Field* f = m->find("word_order"); f != nullptr && words_of(e.enc.type) == 1) {
      r_.error(f->key_loc, v.path, "word_order applies to 32-bit types only");
      ok = false;
    }
    if (const y::Field* f = m->find("writable")) {
      if (auto s = r_.choice(f->value, {"true", "false"})) {
        e.writable = *s == "true";
      }
      if (e.writable && (e.table == Table::kDiscreteInput || e.table == Table::kInputRegister)) {
        r_.error(f->value, std::string(to_string(e.table)) +
                               " is read-only in Modbus: use a coil or a holding_register");
        ok = false;
      } else if (e.writable && var != nullptr && var->kind != rt::VarKind::kParam) {
        r_.error(f->value, "'" + e.var +
                               "' is a pin: only parameters are written (a pin is forced, "
                               "through the bridge, never over Modbus)");
        ok = false;
      } else if (e.writable && var != nullptr && var->load_time_only) {
        r_.error(f->value, "'" + e.var + "' is load-time only: it cannot be written at run time");
        ok = false;
      }
    }
    if (ok && e.address + words_of(e.enc.type) - 1 > 65535) {
      r_.error(v, "the value runs past address 65535");
      ok = false;
    }
    if (ok) {
      for (std::uint32_t w = 0; w < words_of(e.enc.type); ++w) {
        const auto key = std::make_pair(static_cast<int>(e.table), e.address + w);
        const auto [it, inserted] = used_.emplace(key, e.loc);
        if (!inserted) {
          r_.error(v, std::string(to_string(e.table)) + " " + std::to_string(e.address + w) +
                          " is already mapped (line " + std::to_string(it->second.line) + ")");
          ok = false;
          break;
        }
      }
    }
    return ok;
  }

  y::Reader r_;
  const rt::VariableRegistry& vars_;
  std::map<std::pair<int, std::uint32_t>, rt::SourceLoc> used_;
};

}  // namespace

std::optional<ServerConfig> parse_server_text(const std::string& text, const std::string& path,
                                              const rt::VariableRegistry& vars) {
  const std::optional<y::Value> section = rt::config_section(text, path, "modbus_server");
  if (!section) {
    return std::nullopt;
  }
  rt::DiagnosticSink sink;
  SectionParser p(path, sink, vars);
  ServerConfig c;
  p.parse(*section, c);
  sink.throw_if_any();
  return c;
}

std::optional<ServerConfig> load_server_config(const rt::Config& cfg,
                                               const rt::VariableRegistry& vars) {
  if (cfg.modbus_server_loc.line == 0) {
    return std::nullopt;
  }
  return parse_server_text(rt::read_config_text(cfg), cfg.path, vars);
}

std::string format_register_map(const ServerConfig& c) {
  std::ostringstream out;
  out << "modbus_server " << c.bind << ":" << c.port << " (addresses 0-based, as on the wire)\n";
  out << "table             address  words  type     scale        offset       access  variable"
         " [unit]\n";
  for (const ServerEntry& e : c.map) {
    char line[160];
    std::snprintf(line, sizeof line, "%-17s %7u  %5u  %-7s  %-11.6g  %-11.6g  %-6s  ",
                  std::string(to_string(e.table)).c_str(), e.address, words_of(e.enc.type),
                  std::string(to_string(e.enc.type)).c_str(), e.enc.scale, e.enc.offset,
                  e.writable ? "rw" : "r");
    out << line << e.var;
    if (!e.unit.empty()) {
      out << " [" << e.unit << "]";
    }
    if (words_of(e.enc.type) == 2) {
      out << (e.enc.order == WordOrder::kBig ? " (high word first)" : " (low word first)");
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace edm::modbus
