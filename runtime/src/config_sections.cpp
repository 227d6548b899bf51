// Config parser, one function per section: keys, types and ranges. See config_parser.cpp.

#include <algorithm>
#include <cmath>
#include <utility>

#include "config_parser_impl.hpp"
#include "edm/machining/machine_sections.hpp"

namespace edm::rt::config_detail {

std::optional<std::string> Parser::identifier(const Value& v, const char* what) {
  auto s = r_.string(v);
  if (s && !yaml_util::is_identifier(*s)) {
    r_.error(v, std::string(what) + " " + yaml_util::quote(*s) +
                    " is not an identifier (letters, digits and _, not starting with a digit)");
    return std::nullopt;
  }
  return s;
}

void Parser::parse_machine(const Value& v, MachineSpec& out) {
  out.loc = v.loc;
  auto m = r_.map(
      v, {"name", "kind", "io", "electrode", "condition_edit", "axes", "safety", "realtime"});
  if (!m) {
    return;
  }
  if (const Field* f = r_.require(*m, "name")) {
    out.name = r_.string(f->value).value_or("");
  }
  out.io.loc = v.loc;
  out.io.driver_loc = v.loc;
  if (const Field* f = m->find("io")) {
    parse_io(f->value, out.io);
  }
  if (const Field* f = m->find("kind")) {
    out.kind = machining::read_machine_kind(r_, f->value);
  }
  if (const Field* f = m->find("axes")) {
    out.axes = machining::read_axes(r_, f->value);
  }
  if (const Field* f = m->find("safety")) {
    parse_safety(f->value, out);  // after the axes: it names them
  }
  if (const Field* f = m->find("realtime")) {
    parse_realtime(f->value, out.realtime);
  }
  if (const Field* f = m->find("electrode")) {
    parse_electrode(f->value, out.electrode);
  }
  if (const Field* f = m->find("condition_edit")) {
    parse_condition_edit(f->value, out.condition_edit);
  }
}

void Parser::parse_condition_edit(const Value& v, std::vector<std::string>& out) {
  auto items = r_.list(v);
  if (!items) return;
  for (const Value& item : *items) {
    const auto name = r_.string(item);
    if (!name) continue;
    machining::Condition probe;
    if (machining::condition_field(probe, *name) == nullptr) {
      r_.error(item, yaml_util::quote(*name) +
                         " is no editable condition field (open_voltage_v, peak_current_a, "
                         "on_time_us, off_time_us, tdr_us, servo_ref_v, wear_ratio, area_ratio)");
    } else if (std::find(out.begin(), out.end(), *name) != out.end()) {
      r_.error(item, yaml_util::quote(*name) + " is listed twice");
    } else {
      out.push_back(*name);
    }
  }
}

void Parser::parse_electrode(const Value& v, ElectrodeSpec& out) {
  out.loc = v.loc;
  auto m = r_.map(v, {"length_mm", "tool_setter"});
  if (!m) {
    return;
  }
  if (const Field* f = r_.require(*m, "length_mm")) {
    if (auto l = r_.real(f->value)) {
      if (!(*l > 0.0 && *l <= 10000.0)) {
        r_.error(f->value, "must be in (0, 10000] mm (the electrode's length)");
      } else {
        out.length_mm = *l;
      }
    }
  }
  if (const Field* f = m->find("tool_setter")) {
    auto t = r_.map(f->value, {"x_mm", "y_mm", "z_mm"});
    if (!t) return;
    ToolSetterSpec ts;
    ts.loc = f->value.loc;
    bool ok = true;
    for (auto [key, dst] : {std::pair{"x_mm", &ts.x_mm}, {"y_mm", &ts.y_mm}, {"z_mm", &ts.z_mm}}) {
      const Field* g = r_.require(*t, key);
      const auto x = g != nullptr ? r_.real(g->value) : std::nullopt;
      if (!x) {
        ok = false;
      } else if (!std::isfinite(*x) || std::abs(*x) > 1e5) {
        r_.error(g->value, "must be a finite number of mm (|v| <= 1e5)");
        ok = false;
      } else {
        *dst = *x;
      }
    }
    if (ok) out.tool_setter = ts;
  }
}

void Parser::parse_realtime(const Value& v, RealtimeSpec& out) {
  out.loc = v.loc;
  auto m = r_.map(v, {"pm_qos_latency", "pm_qos_device", "lock_memory"});
  if (!m) {
    return;
  }
  if (const Field* f = m->find("pm_qos_latency")) {
    // The kernel takes a whole number of microseconds (an s32); `off` makes no request.
    const std::string text = f->value.node.IsScalar() ? f->value.node.Scalar() : "";
    if (text == "off" && !Reader::is_quoted(f->value.node)) {
      out.pm_qos_latency_us.reset();
    } else if (auto d = r_.duration(f->value)) {
      constexpr std::int64_t kMaxUs = 2'000'000'000;  // the kernel's own default (2000 s)
      const std::int64_t ns = d->count();
      if (ns % 1000 != 0) {
        r_.error(f->value, "must be whole microseconds (got " + text + ")");
      } else if (ns / 1000 > kMaxUs) {
        r_.error(f->value, "must be <= 2000s (got " + text + ")");
      } else {
        out.pm_qos_latency_us = static_cast<std::int32_t>(ns / 1000);
      }
    }
  }
  if (const Field* f = m->find("pm_qos_device")) {
    if (auto s = r_.string(f->value)) {
      if (s->front() != '/') {
        r_.error(f->value, "must be an absolute path (got " + yaml_util::quote(*s) + ")");
      } else {
        out.pm_qos_device = *s;
      }
    }
  }
  if (const Field* f = m->find("lock_memory")) {
    if (auto s = r_.choice(f->value, {"true", "false"})) {
      out.lock_memory = *s == "true";
    }
  }
}

void Parser::parse_io(const Value& v, IoSpec& out) {
  out.loc = v.loc;
  out.driver_loc = v.loc;
  auto m = r_.map(v, {"driver", "task", "params", "pins", "drivers"});
  if (!m) {
    return;
  }
  if (const Field* f = m->find("driver")) {
    out.driver_loc = f->value.loc;
    if (auto s = r_.string(f->value)) {
      out.driver = *s;
    }
  }
  if (const Field* f = m->find("task")) {
    if (auto s = identifier(f->value, "task name")) {
      out.task = NameRef{*s, f->value.loc};
    }
  }
  if (const Field* f = m->find("params")) {
    parse_params(f->value, out.params);
  }
  parse_io_extras(*m, out);  // config_io.cpp: pins, drivers (composite)
}

void Parser::parse_task(const Value& v, TaskSpec& out) {
  out.loc = v.loc;
  out.name_loc = v.loc;
  auto m = r_.map(v, {"name", "interval", "priority", "cpu", "overrun", "watchdog", "programs"});
  if (!m) {
    task_names_complete_ = task_programs_complete_ = false;
    return;
  }
  if (const Field* f = r_.require(*m, "name")) {
    out.name_loc = f->value.loc;
    out.name = identifier(f->value, "task name").value_or("");
  }
  if (out.name.empty()) {
    task_names_complete_ = false;
  }
  if (const Field* f = r_.require(*m, "interval")) {
    if (auto d = r_.duration(f->value)) {
      if (d->count() <= 0) {
        r_.error(f->value, "must be > 0 (got " + f->value.node.Scalar() + ")");
      } else {
        out.interval = *d;
      }
    }
  }
  int_in(*m, "priority", 0, 31, out.priority);
  if (const Field* f = m->find("cpu")) {
    if (auto x = r_.integer(f->value, 0, kMaxInt)) {
      out.cpu = static_cast<int>(*x);
    }
  }
  if (const Field* f = m->find("overrun")) {
    if (auto s = r_.choice(f->value, {"skip", "asap"})) {
      out.overrun = *s == "asap" ? OverrunPolicy::kAsap : OverrunPolicy::kSkip;
    }
  }
  if (const Field* f = m->find("watchdog")) {
    parse_watchdog(f->value, out.watchdog);
  }
  const Field* f = r_.require(*m, "programs");
  auto items = f != nullptr ? r_.list(f->value) : std::nullopt;
  if (!items) {
    task_programs_complete_ = false;
    return;
  }
  if (items->empty()) {
    r_.error(f->value, "must list at least one program");
  }
  for (const Value& item : *items) {
    if (auto s = r_.string(item)) {
      out.programs.push_back({*s, item.loc});
    } else {
      task_programs_complete_ = false;
    }
  }
}

void Parser::parse_watchdog(const Value& v, WatchdogSpec& out) {
  out.loc = v.loc;
  auto m = r_.map(v, {"time", "sensitivity", "action", "host_stall"});
  if (!m) {
    return;
  }
  out.enabled = true;
  if (const Field* f = r_.require(*m, "time")) {
    if (auto d = r_.duration(f->value)) {
      if (d->count() <= 0) {
        r_.error(f->value, "must be > 0 (got " + f->value.node.Scalar() + ")");
      } else {
        out.time = *d;
      }
    }
  }
  int_in(*m, "sensitivity", 1, kMaxInt, out.sensitivity);
  if (const Field* f = m->find("action")) {
    if (auto s = r_.choice(f->value, {"fault", "warn"})) {
      out.action = *s == "warn" ? WatchdogAction::kWarn : WatchdogAction::kFault;
    }
  }
  if (const Field* f = m->find("host_stall")) {
    if (auto s = r_.choice(f->value, {"fault", "tolerate"})) {
      out.host_stall = *s == "tolerate" ? HostStallPolicy::kTolerate : HostStallPolicy::kFault;
    }
  }
}

void Parser::program_or_block_name(const MapView& m, const char* what, std::string& name,
                                   SourceLoc& name_loc) {
  if (const Field* f = r_.require(m, "name")) {
    name_loc = f->value.loc;
    if (auto s = identifier(f->value, what)) {
      // Reserved names still count as known so tasks naming them don't cascade.
      name = *s;
      if (*s == "io") {
        r_.error(f->value, "'io' is reserved (it names the process image); pick another name");
      }
    }
  }
}

void Parser::parse_program(const Value& v, ProgramSpec& out) {
  out.loc = v.loc;
  out.name_loc = v.loc;
  auto m = r_.map(v, {"name", "blocks", "wires", "include"});
  if (!m) {
    program_names_complete_ = false;
    return;
  }
  program_or_block_name(*m, "program name", out.name, out.name_loc);
  if (out.name.empty()) {
    program_names_complete_ = false;
  }
  if (const Field* f = m->find("blocks")) {
    if (auto items = r_.list(f->value)) {
      parse_named(
          *items, out.blocks, [this](const Value& item, BlockSpec& b) { parse_block(item, b); },
          "block", " in program '" + out.name + "'");
    }
  }
  if (const Field* f = m->find("wires")) {
    parse_wires(f->value, out.wires);
  }
  if (const Field* f = m->find("include")) {  // after its own: appended (config_include.cpp)
    parse_include(f->value, out);
  }
}

void Parser::parse_block(const Value& v, BlockSpec& out) {
  out.loc = v.loc;
  out.name_loc = v.loc;
  out.type_loc = v.loc;
  auto m = r_.map(v, {"name", "type", "params"});
  if (!m) {
    return;
  }
  program_or_block_name(*m, "block name", out.name, out.name_loc);
  if (const Field* f = r_.require(*m, "type")) {
    out.type_loc = f->value.loc;
    out.type = r_.string(f->value).value_or("");
  }
  if (const Field* f = m->find("params")) {
    parse_params(f->value, out.params);
  }
}

// Parameters are a map of name: scalar. A C++ PROGRAM's child parameters are set as a nested map
// (`gap: {kg: 0.1}`) or a dotted key (`gap.kg: 0.1`); both give the setting "gap.kg", and one
// parameter set both ways is an error.
void Parser::parse_params(const Value& v, std::vector<ParamSetting>& out) {
  parse_params_under(v, "", 0, out);
}

void Parser::parse_params_under(const Value& v, const std::string& prefix, int depth,
                                std::vector<ParamSetting>& out) {
  constexpr int kMaxDepth = 4;  // program.block.child.grandchild.param at the most
  auto m = r_.map(v, {});
  if (!m) {
    return;
  }
  for (const Field& f : m->fields) {
    if (!yaml_util::is_dotted_name(f.key, 1, kMaxDepth - depth)) {
      r_.error(f.key_loc, v.path,
               "parameter name " + yaml_util::quote(f.key) +
                   " is not an identifier (or child.parameter)");
      continue;
    }
    const std::string key = prefix + f.key;
    if (f.value.node.IsMap() && depth + 1 < kMaxDepth) {
      parse_params_under(f.value, key + ".", depth + 1, out);
      continue;
    }
    if (!r_.scalar(f.value,
                   "a scalar (number, true/false, duration or string), or a map of a "
                   "child's parameters")) {
      continue;
    }
    const auto same = [&](const ParamSetting& s) { return s.key == key; };
    if (const auto it = std::find_if(out.begin(), out.end(), same); it != out.end()) {
      r_.error(f.key_loc, v.path,
               "parameter '" + key + "' is set twice (first at line " + line_of(it->key_loc) + ")");
      continue;
    }
    out.push_back(
        {key, f.value.node.Scalar(), Reader::is_quoted(f.value.node), f.key_loc, f.value.loc});
  }
}

void Parser::parse_wires(const Value& v, std::vector<WireSpec>& out) {
  auto m = r_.map(v, {}, "; an input can be wired only once");
  if (!m) {
    return;
  }
  for (const Field& f : m->fields) {
    // Up to 4 parts: a child pin of a C++ PROGRAM block is block.child.pin (nested: one more).
    if (!yaml_util::is_dotted_name(f.key, 2, 4)) {
      r_.error(
          f.key_loc, v.path,
          "destination " + yaml_util::quote(f.key) + " must be block.pin or io.pin (an input)");
      continue;
    }
    if (!r_.scalar(f.value, "a source (block.pin, program.block.pin, io.pin or a constant)")) {
      continue;
    }
    WireSpec w{f.key, f.value.node.Scalar(), true, f.key_loc, f.value.loc};
    const bool quoted = Reader::is_quoted(f.value.node);
    const ScalarKind kind = quoted ? ScalarKind::kString : yaml_util::classify_plain(w.source);
    if (kind == ScalarKind::kBool || kind == ScalarKind::kInt || kind == ScalarKind::kReal ||
        kind == ScalarKind::kNonFinite) {
      // Constants must be finite and representable; real() says what is wrong otherwise.
      if (kind != ScalarKind::kBool && !r_.real(f.value)) {
        continue;
      }
      w.source_is_name = false;
    } else if (!yaml_util::is_dotted_name(w.source, 2, 5)) {
      r_.error(f.value.loc, v.path,
               "source " + yaml_util::quote(w.source) + " of " + f.key +
                   " must be block.pin, program.block.pin, io.pin, a number or true/false");
      continue;
    }
    out.push_back(std::move(w));
  }
}

std::vector<NameRef> Parser::parse_variable_names(const Value& v) {
  std::vector<NameRef> out;
  if (auto items = r_.list(v)) {
    for (const Value& item : *items) {
      if (auto s = r_.string(item)) {
        if (yaml_util::is_dotted_name(*s, 2, 5)) {
          out.push_back({*s, item.loc});
        } else {
          r_.error(item,
                   yaml_util::quote(*s) + " is not a variable name (program.block.pin or io.pin)");
        }
      }
    }
  }
  return out;
}

void Parser::parse_trace(const Value& v, TraceSpec& out) {
  out.loc = v.loc;
  auto m = r_.map(v, {"variables", "capacity"});
  if (!m) {
    return;
  }
  if (const Field* f = m->find("variables")) {
    out.variables = parse_variable_names(f->value);
  }
  if (const Field* f = m->find("capacity")) {
    if (auto x = r_.integer(f->value, 16, 1 << 20)) {
      if ((*x & (*x - 1)) != 0) {
        r_.error(f->value, "must be a power of two (got " + f->value.node.Scalar() + ")");
      } else {
        out.capacity = static_cast<std::size_t>(*x);
      }
    }
  }
}

void Parser::parse_bridge(const Value& v, BridgeSpec& out) {
  out.loc = v.loc;
  auto m = r_.map(
      v, {"bind", "port", "token_file", "viewer_token_file", "max_sessions", "max_line_bytes",
          "read_timeout", "queue_limit", "stall_timeout", "status_vars", "queue_bytes",
          "max_pending", "hello_timeout", "tls", "insecure_plaintext", "audit_file"});
  if (!m) {
    return;
  }
  if (const Field* f = m->find("bind")) {
    out.bind = r_.string(f->value).value_or(out.bind);
  }
  int_in(*m, "port", 0, 65535, out.port);
  if (const Field* f = m->find("token_file")) {
    out.token_file = r_.string(f->value).value_or("");
  }
  if (const Field* f = m->find("viewer_token_file")) {
    out.viewer_token_file = r_.string(f->value).value_or("");
  }
  int_in(*m, "max_sessions", 1, 64, out.max_sessions);
  int_in(*m, "max_line_bytes", 1024, kMaxLineBytes, out.max_line_bytes);
  for (auto [key, dest] : {std::pair{"read_timeout", &out.read_timeout},
                           std::pair{"stall_timeout", &out.stall_timeout},
                           std::pair{"hello_timeout", &out.hello_timeout}}) {
    if (const Field* f = m->find(key)) {
      if (auto d = r_.duration(f->value)) {
        if (*d < std::chrono::milliseconds(100) || *d > std::chrono::hours(24)) {
          r_.error(f->value, std::string(key) + " must be between 100ms and 24h");
        } else {
          *dest = *d;
        }
      }
    }
  }
  int_in(*m, "queue_limit", 16, 65536, out.queue_limit);
  int_in(*m, "queue_bytes", 64 * 1024, 256 * 1024 * 1024, out.queue_bytes);
  int_in(*m, "max_pending", 1, 1024, out.max_pending);
  if (const Field* f = m->find("tls")) {
    out.tls_loc = f->value.loc;
    if (auto t = r_.map(f->value, {"cert", "key"})) {
      for (auto [key, dest] : {std::pair{"cert", &out.tls_cert}, std::pair{"key", &out.tls_key}}) {
        if (const Field* g = t->find(key)) {
          *dest = r_.string(g->value).value_or("");
        } else {
          r_.error(f->value, std::string("tls needs '") + key + "'");
        }
      }
    }
  }
  if (const Field* f = m->find("insecure_plaintext")) {
    out.insecure_plaintext = r_.choice(f->value, {"true", "false"}).value_or("false") == "true";
  }
  if (const Field* f = m->find("audit_file")) {
    out.audit_file = r_.string(f->value).value_or("");
  }
  if (const Field* f = m->find("status_vars")) {
    out.status_vars = parse_variable_names(f->value);
    if (out.status_vars.size() > 16) {
      r_.error(f->value, "at most 16 status variables");
    }
  }
}

void Parser::parse_retain(const Value& v, RetainSpec& out) {
  out.loc = v.loc;
  auto m = r_.map(v, {"file", "min_interval", "variables", "job_depth", "job_touch_z", "job_wear"});
  if (!m) {
    return;
  }
  if (const Field* f = r_.require(*m, "file")) {
    out.file = r_.string(f->value).value_or("");
    out.file_loc = f->value.loc;
  }
  if (const Field* f = m->find("min_interval")) {
    if (auto d = r_.duration(f->value)) {
      out.min_interval = *d;
    }
  }
  if (const Field* f = m->find("variables")) {
    out.variables = parse_variable_names(f->value);
  }
  for (auto [key, dest] :
       {std::pair<const char*, std::optional<NameRef>*>{"job_depth", &out.job_depth},
        {"job_touch_z", &out.job_touch_z},
        {"job_wear", &out.job_wear}}) {
    const Field* f = m->find(key);
    if (f == nullptr) continue;
    if (auto s = r_.string(f->value)) {
      if (yaml_util::is_dotted_name(*s, 2, 5)) {
        *dest = NameRef{*s, f->value.loc};
      } else {
        r_.error(f->value,
                 yaml_util::quote(*s) + " is not a variable name (program.block.pin or io.pin)");
      }
    }
  }
}

}  // namespace edm::rt::config_detail
