#include "edm/hal/pin_map.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <set>
#include <utility>

#include "edm/machining/located_yaml.hpp"

namespace edm::hal {

namespace {

std::optional<double> number(const rt::PinMapField& f) {
  double v = 0.0;
  const char* b = f.value.data();
  const char* e = b + f.value.size();
  auto [p, ec] = std::from_chars(b, e, v);
  if (f.quoted || ec != std::errc{} || p != e || f.value.empty() || !std::isfinite(v)) {
    return std::nullopt;
  }
  return v;
}

// HAL names: letters, digits, '-', '_', '.' (halcmd splits on white space and '=').
bool is_hal_name(const std::string& s) {
  if (s.empty()) return false;
  for (const char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '-' || c == '_' || c == '.';
    if (!ok) return false;
  }
  return s.front() != '.' && s.back() != '.';
}

std::string default_hal_name(const std::string& io) {
  std::string s = io;
  for (char& c : s) {
    if (c == '_') c = '-';
  }
  return s;
}

}  // namespace

IoType HalPin::io_type() const noexcept {
  if (type == HalType::kBit) return IoType::kBool;
  if (type == HalType::kFloat || scale != 1.0 || offset != 0.0) return IoType::kReal;
  return IoType::kInt;
}

HalPin parse_pin_entry(const rt::PinMapEntry& entry, std::size_t index,
                       std::vector<rt::PinMapError>& errs) {
  HalPin m;
  const auto err = [&](const std::string& key, std::string message) {
    errs.push_back({index, key, std::move(message)});
  };
  bool has_name = false;
  bool has_type = false;
  bool has_dir = false;
  bool has_hal = false;
  bool has_safe = false;
  bool has_safe_in = false;
  bool has_counter = false;
  for (const rt::PinMapField& f : entry) {
    if (f.key == "name") {
      has_name = true;
      if (!machining::yaml::is_identifier(f.value)) {
        err(f.key, "pin name " + machining::yaml::quote(f.value) + " is not an identifier");
      }
      m.name = f.value;
    } else if (f.key == "hal" || f.key == "signal") {
      if (!is_hal_name(f.value)) {
        err(f.key, "HAL name " + machining::yaml::quote(f.value) +
                       " must be letters, digits, '-', '_' and inner '.'");
      }
      (f.key == "hal" ? m.hal : m.signal) = f.value;
      has_hal = has_hal || f.key == "hal";
    } else if (f.key == "type") {
      has_type = true;
      if (f.value == "bit") {
        m.type = HalType::kBit;
      } else if (f.value == "float") {
        m.type = HalType::kFloat;
      } else if (f.value == "s32") {
        m.type = HalType::kS32;
      } else if (f.value == "u32") {
        m.type = HalType::kU32;
      } else {
        has_type = false;
        err(f.key,
            "unknown HAL pin type " + machining::yaml::quote(f.value) + " (bit, float, s32, u32)");
      }
    } else if (f.key == "direction") {
      has_dir = true;
      if (f.value == "in" || f.value == "out") {
        m.input = f.value == "in";
      } else {
        err(f.key, "must be in (a machine input, read by edmplc) or out, got " +
                       machining::yaml::quote(f.value));
      }
    } else if (f.key == "scale" || f.key == "offset") {
      const auto v = number(f);
      if (!v || (f.key == "scale" && *v == 0.0)) {
        err(f.key, std::string("must be a finite number") +
                       (f.key == "scale" ? " other than 0" : "") + ", got " +
                       machining::yaml::quote(f.value));
      } else {
        (f.key == "scale" ? m.scale : m.offset) = *v;
      }
    } else if (f.key == "counter") {
      has_counter = true;
      if (f.quoted || (f.value != "true" && f.value != "false")) {
        err(f.key, "must be true or false, got " + machining::yaml::quote(f.value));
      }
      m.counter = f.value == "true";
    } else if (f.key == "safe") {
      has_safe = true;
      if (!f.quoted && (f.value == "true" || f.value == "false")) {
        m.safe = f.value == "true" ? 1.0 : 0.0;
      } else if (const auto v = number(f)) {
        m.safe = *v;
      } else {
        err(f.key, "must be a number or true/false, got " + machining::yaml::quote(f.value));
      }
    } else if (f.key == "safe_in") {
      has_safe_in = true;
      if (f.value == "fault") {
        m.safe_in = SafeIn::kFaultAndEstop;
      } else if (f.value == "estop") {
        m.safe_in = SafeIn::kEstopOnly;
      } else {
        err(f.key, "must be fault (FAULT and ESTOP) or estop (ESTOP only), got " +
                       machining::yaml::quote(f.value));
      }
    } else if (f.key == "role") {
      if (f.value == "heartbeat") {
        m.role = Role::kHeartbeat;
      } else if (f.value == "heartbeat_out") {
        m.role = Role::kHeartbeatOut;
      } else {
        err(f.key,
            "must be heartbeat (the HAL side's, an input) or heartbeat_out (edmplc's), "
            "got " +
                machining::yaml::quote(f.value));
      }
    } else if (f.key == "unit") {
      m.unit = f.value;
    } else {
      err(f.key, "unknown key " + machining::yaml::quote(f.key) +
                     " (name, hal, type, direction, scale, offset, counter, safe, safe_in, "
                     "signal, role, unit)");
    }
  }
  if (!has_name) err("", "missing required key 'name' (the io.<name> it maps to)");
  if (!has_type) {
    if (errs.empty() || errs.back().key != "type") err("", "missing required key 'type'");
    return m;
  }
  if (!has_dir) err("", "missing required key 'direction' (in or out)");
  if (!has_hal) m.hal = default_hal_name(m.name);
  const bool integer = m.type == HalType::kS32 || m.type == HalType::kU32;
  if (m.type == HalType::kBit && (m.scale != 1.0 || m.offset != 0.0)) {
    err("", "a bit pin takes no scale or offset");
  }
  if (has_counter && m.counter && !(integer && m.input)) {
    err("counter", "only an s32 or u32 input can be a counter");
  }
  if (m.counter && (m.scale != 1.0 || m.offset != 0.0)) {
    err("counter", "a counter counts: no scale or offset");
  }
  if ((has_safe || has_safe_in) && m.input) {
    err(has_safe ? "safe" : "safe_in", "applies to outputs only");
  }
  if (m.role == Role::kHeartbeat && !m.input) {
    err("role", "a heartbeat (the HAL side's) is an input: direction: in");
  }
  if (m.role == Role::kHeartbeatOut && (m.input || m.type != HalType::kU32)) {
    err("role", "heartbeat_out is a u32 output (direction: out, type: u32)");
  }
  if (m.role == Role::kHeartbeat && m.type == HalType::kFloat) {
    err("role", "a heartbeat is a bit, s32 or u32 that changes every HAL cycle");
  }
  return m;
}

std::vector<HalPin> parse_pin_map(const std::vector<rt::PinMapEntry>& entries,
                                  std::vector<rt::PinMapError>& errs) {
  std::vector<HalPin> map;
  std::set<std::string> names;
  std::set<std::string> hal_names;
  std::set<std::string> written_signals;
  bool heartbeat = false;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::size_t before = errs.size();
    HalPin m = parse_pin_entry(entries[i], i, errs);
    if (errs.size() == before) {
      if (!names.insert(m.name).second) {
        errs.push_back({i, "name", "pin '" + m.name + "' is mapped twice"});
      }
      if (!hal_names.insert(m.hal).second) {
        errs.push_back({i, "hal", "HAL pin '" + m.hal + "' is declared twice"});
      }
      if (!m.input && !m.signal.empty() && !written_signals.insert(m.signal).second) {
        errs.push_back({i, "signal", "signal '" + m.signal + "' already has a writer here"});
      }
      if (m.role == Role::kHeartbeat) {
        if (heartbeat) errs.push_back({i, "role", "a second heartbeat (one is watched)"});
        heartbeat = true;
      }
    }
    map.push_back(std::move(m));
  }
  if (entries.empty()) {
    errs.push_back({0, "", "the hal driver needs at least one pin (`pins:`)"});
  }
  return map;
}

double to_raw(const HalPin& p, double value) noexcept {
  if (!std::isfinite(value)) return 0.0;
  double raw = (value - p.offset) / p.scale;
  if (!std::isfinite(raw)) return 0.0;
  switch (p.type) {
    case HalType::kBit: return raw != 0.0 ? 1.0 : 0.0;
    case HalType::kFloat: return raw;
    case HalType::kS32:
      raw = std::nearbyint(raw);
      return raw < -2147483648.0 ? -2147483648.0 : (raw > 2147483647.0 ? 2147483647.0 : raw);
    case HalType::kU32:
      raw = std::nearbyint(raw);
      return raw < 0.0 ? 0.0 : (raw > 4294967295.0 ? 4294967295.0 : raw);
  }
  return 0.0;
}

}  // namespace edm::hal
