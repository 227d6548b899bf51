// The variable and trace ops (ops_handlers.hpp; docs/protocol.md "Variables", "Trace streaming"):
//   var.list, var.read, var.write, var.force, var.unforce → rt::VariableRegistry (non-RT API)
//   trace.start, trace.stop                               → the session's trace variables
#include <algorithm>
#include <cmath>
#include <set>

#include "ops_body.hpp"
#include "ops_handlers.hpp"
#include "server_impl.hpp"

namespace edm::bridge::ops {
namespace {

constexpr std::size_t kMaxDurationChars = 64;

ErrorCode var_error(rt::VarResult r) {
  switch (r) {
    case rt::VarResult::kNotFound: return ErrorCode::kNotFound;
    case rt::VarResult::kBusy: return ErrorCode::kBusy;
    case rt::VarResult::kInvalidState:
      return ErrorCode::kInvalidState;  // e.g. a force refused in FAULT or ESTOP
    default: return ErrorCode::kBadRequest;
  }
}

Body var_write(Session& s, const Json& msg, bool force);

}  // namespace

Body op_var_list(Session& s, const Json& msg) {
  std::string prefix;
  if (auto it = msg.find("prefix"); it != msg.end()) {
    if (!it->is_string()) {
      return error(ErrorCode::kBadRequest, "'prefix' must be a string");
    }
    prefix = it->get<std::string>();
  }
  auto& reg = s.server().rt.variables();
  const auto forced_list = reg.forced();
  const std::set<std::string> forced(forced_list.begin(), forced_list.end());
  Json vars = Json::array();
  for (const auto& v : reg.all()) {
    if (v.name.compare(0, prefix.size(), prefix) != 0) {
      continue;
    }
    vars.push_back({{"name", v.name},
                    {"kind", std::string(to_string(v.kind))},
                    {"type", std::string(v.type_name())},
                    {"unit", v.unit},
                    {"task", v.owner != nullptr ? v.owner->name() : ""},
                    {"forced", forced.count(v.name) > 0}});
  }
  return Json{{"vars", std::move(vars)}};
}

Body op_var_read(Session& s, const Json& msg) {
  std::vector<std::string> names;
  if (auto it = msg.find("names"); it != msg.end() && it->is_array() && !it->empty()) {
    for (const auto& n : *it) {
      if (!n.is_string()) {
        return error(ErrorCode::kBadRequest, "'names' must be an array of strings");
      }
      names.push_back(n.get<std::string>());
    }
  } else if (auto n = msg.find("name"); n != msg.end() && n->is_string()) {
    names.push_back(n->get<std::string>());
  } else {
    return error(ErrorCode::kBadRequest, "'name' (string) or 'names' (array) is required");
  }
  auto& reg = s.server().rt.variables();
  Json values = Json::object();
  for (const auto& name : names) {
    const rt::Variable* v = reg.find(name);
    if (v == nullptr) {
      return error(ErrorCode::kNotFound, "no variable " + brief_name(name));
    }
    const auto value = reg.read(name);
    values[name] = value && std::isfinite(*value) ? Json(*value) : Json(nullptr);
  }
  return Json{{"values", std::move(values)}};
}

Body op_var_write(Session& s, const Json& msg) { return var_write(s, msg, false); }
Body op_var_force(Session& s, const Json& msg) { return var_write(s, msg, true); }

namespace {

Body var_write(Session& s, const Json& msg, bool force) {
  const Json* name = field(msg, "name", [](const Json& j) { return j.is_string(); });
  const Json* value =
      field(msg, "value", [](const Json& j) { return j.is_number() || j.is_boolean(); });
  if (name == nullptr ||
      (value == nullptr && !(msg.contains("value") && msg["value"].is_string() && !force))) {
    return error(ErrorCode::kBadRequest,
                 "'name' (string) and 'value' (number or boolean; durations: \"2ms\") required");
  }
  auto& reg = s.server().rt.variables();
  const auto& n = name->get_ref<const std::string&>();
  if (reg.find(n) == nullptr) {  // before the registry, whose messages quote the whole name
    return error(ErrorCode::kNotFound, "no variable " + brief_name(n));
  }
  // A retained parameter is not changed while the retain file cannot be written: it would be
  // lost at the next start, and the operator told ok.
  if (const rt::RetainStore* store = s.server().rt.retain();
      !force && store != nullptr && store->failing() && store->retains(n)) {
    return error(ErrorCode::kRetainFailed,
                 brief_name(n) +
                     " is retained and the retain file cannot be written now (alarm 183); "
                     "not changed");
  }
  rt::VarStatus st;
  if (value == nullptr) {  // a duration parameter as text
    const auto& text = msg["value"].get_ref<const std::string&>();
    if (text.size() > kMaxDurationChars) {  // parse_duration's messages quote the whole text
      return error(ErrorCode::kBadRequest, "'value': a duration is at most " +
                                               std::to_string(kMaxDurationChars) +
                                               " characters (e.g. \"2ms\")");
    }
    const auto d = rt::parse_duration(text);
    if (!d.value) {
      return error(ErrorCode::kBadRequest, "'value': " + d.error);
    }
    st = reg.write(n, rt::ParamValue::of_duration(*d.value));
  } else {
    const double x = value->is_boolean() ? (value->get<bool>() ? 1.0 : 0.0) : value->get<double>();
    st = force ? reg.force(n, x) : reg.write(n, x);
  }
  if (!st) {
    return error(var_error(st.result), st.message.empty() ? "refused" : st.message);
  }
  return Json{{"name", n}};
}

}  // namespace

Body op_var_unforce(Session& s, const Json& msg) {
  const Json* name = field(msg, "name", [](const Json& j) { return j.is_string(); });
  if (name == nullptr) {
    return error(ErrorCode::kBadRequest, "'name' (string) required");
  }
  if (s.server().rt.variables().find(name->get_ref<const std::string&>()) == nullptr) {
    return error(ErrorCode::kNotFound, "no variable " + brief_name(name->get<std::string>()));
  }
  const auto st = s.server().rt.variables().unforce(name->get<std::string>());
  if (!st) {
    return error(var_error(st.result), st.message.empty() ? "refused" : st.message);
  }
  return Json{{"name", *name}};
}

Body op_trace_start(Session& s, const Json& msg) {
  const Json* vars = field(msg, "vars", [](const Json& j) { return j.is_array() && !j.empty(); });
  if (vars == nullptr) {
    return error(ErrorCode::kBadRequest, "'vars' must be a non-empty array of pin names");
  }
  auto& reg = s.server().rt.variables();
  std::vector<std::string> names;
  for (const auto& v : *vars) {
    if (!v.is_string()) {
      return error(ErrorCode::kBadRequest, "'vars' must be an array of strings");
    }
    const auto& n = v.get_ref<const std::string&>();
    if (std::find(names.begin(), names.end(), n) != names.end()) {
      continue;  // a repeated name is traced once
    }
    if (names.size() == rt::kMaxTraceVarsPerTask) {
      return error(ErrorCode::kTooLarge, "at most " + std::to_string(rt::kMaxTraceVarsPerTask) +
                                             " distinct trace variables per session");
    }
    const rt::Variable* var = reg.find(n);
    if (var == nullptr) {
      return error(ErrorCode::kNotFound, "no variable " + brief_name(n));
    }
    if (!var->is_pin() || var->owner == nullptr) {
      return error(ErrorCode::kBadRequest, brief_name(n) + " is a parameter; only pins are traced");
    }
    names.push_back(n);
  }
  s.set_trace_vars(names);
  return Json{{"vars", names}};
}

Body op_trace_stop(Session& s, const Json& /*msg*/) {
  s.set_trace_vars({});
  return Json::object();
}

}  // namespace edm::bridge::ops
