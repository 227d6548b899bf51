#include "edm/runtime/variables.hpp"

#include <cmath>

#include "edm/runtime/task.hpp"

namespace edm::rt {

std::string_view to_string(VarKind k) noexcept {
  switch (k) {
    case VarKind::kInput: return "input";
    case VarKind::kOutput: return "output";
    case VarKind::kParam: return "param";
  }
  return "?";
}

std::string list_row(const Variable& v) {
  const auto or_dash = [](const std::string& s) { return s.empty() ? std::string("-") : s; };
  std::string row = v.name + "\t" + std::string(to_string(v.kind)) + "\t" +
                    std::string(v.type_name()) + "\t" + or_dash(v.unit) + "\t" +
                    (v.owner != nullptr ? v.owner->name() : std::string("-"));
  if (v.kind == VarKind::kParam) {
    row += "\t" + or_dash(v.range) + "\t" + (v.load_time_only ? "load-time" : "runtime") + "\t" +
           or_dash(v.description);
  }
  return row;
}

std::string_view Variable::type_name() const noexcept {
  return is_pin() ? to_string(pin.type) : to_string(param_type);
}

bool VariableRegistry::add(Variable v) {
  if (index_.count(v.name) != 0) {
    return false;
  }
  index_.emplace(v.name, vars_.size());
  vars_.push_back(std::move(v));
  return true;
}

const Variable* VariableRegistry::find(std::string_view name) const {
  auto it = index_.find(std::string(name));
  return it == index_.end() ? nullptr : &vars_[it->second];
}

std::optional<double> VariableRegistry::read(std::string_view name) const {
  const Variable* v = find(name);
  if (v == nullptr) {
    return std::nullopt;
  }
  if (v->is_pin()) {
    return read_pin_as_double(v->pin);
  }
  if (v->param_type == ParamType::kString) {
    return std::nullopt;
  }
  std::lock_guard lock(param_mutex_);
  return v->block->read_param(v->param_index).as_double();
}

std::optional<ParamValue> VariableRegistry::read_param(std::string_view name) const {
  const Variable* v = find(name);
  if (v == nullptr || v->is_pin()) {
    return std::nullopt;
  }
  std::lock_guard lock(param_mutex_);
  return v->block->read_param(v->param_index);
}

namespace {

// Converts a number to a parameter value of the given type, or explains why it can't.
std::optional<ParamValue> to_param_value(ParamType t, double x, std::string& why) {
  if (!std::isfinite(x)) {
    why = "value must be finite";
    return std::nullopt;
  }
  switch (t) {
    case ParamType::kBool:
      if (x != 0.0 && x != 1.0) {
        why = "BOOL takes 0 or 1";
        return std::nullopt;
      }
      return ParamValue::of_bool(x != 0.0);
    case ParamType::kInt:
      if (x != std::trunc(x) || std::abs(x) > 9.0e15) {
        why = "LINT takes a whole number";
        return std::nullopt;
      }
      return ParamValue::of_int(static_cast<std::int64_t>(x));
    case ParamType::kReal: return ParamValue::of_real(x);
    case ParamType::kDuration:
      if (x < 0.0 || x > 9.0e9) {
        why = "TIME takes seconds in [0, 9e9]";
        return std::nullopt;
      }
      return ParamValue::of_duration(Duration{std::llround(x * 1e9)});
    case ParamType::kString:
      why = "STRING parameters are set in the config only";
      return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace

const Variable* VariableRegistry::find_param(std::string_view name, VarStatus& status) const {
  const Variable* v = find(name);
  if (v == nullptr) {
    status = {VarResult::kNotFound, "no variable '" + std::string(name) + "'"};
    return nullptr;
  }
  if (v->is_pin()) {
    status = {VarResult::kWrongKind,
              "'" + std::string(name) + "' is a pin: pins are forced, parameters are written"};
    return nullptr;
  }
  return v;
}

VarStatus VariableRegistry::write(std::string_view name, double value, bool apply_now) {
  VarStatus status;
  const Variable* v = find_param(name, status);
  if (v == nullptr) {
    return status;
  }
  std::string why;
  auto pv = to_param_value(v->param_type, value, why);
  if (!pv) {
    return {VarResult::kTypeMismatch, "'" + std::string(name) + "': " + why};
  }
  return write(name, *pv, apply_now);
}

VarStatus VariableRegistry::write(std::string_view name, const ParamValue& value, bool apply_now) {
  VarStatus status;
  const Variable* v = find_param(name, status);
  if (v == nullptr) {
    return status;
  }
  if (value.type != v->param_type) {
    return {VarResult::kTypeMismatch, "'" + std::string(name) + "' is " +
                                          std::string(to_string(v->param_type)) + ", not " +
                                          std::string(to_string(value.type))};
  }
  if (!v->load_time_only) {
    // Here, not only in the block's stage_param(): no writer reaches a block with a value outside
    // the declared physical range, whatever the block type overrides.
    const ParamSpec spec{.unit = v->unit, .range = v->param_range, .finite = v->param_finite};
    if (std::string why = range_violation(spec, value, /*with_unit=*/true); !why.empty()) {
      return {VarResult::kInvalid, "'" + std::string(name) + "': out of range: " + why};
    }
  }
  std::lock_guard lock(param_mutex_);
  const ParamValue previous = v->block->read_param(v->param_index);
  auto errs = v->block->stage_param(v->param_index, value);
  if (!errs.empty()) {
    std::string msg = "'" + std::string(name) + "': ";
    for (std::size_t i = 0; i < errs.size(); ++i) {
      msg += (i ? "; " : "") + (errs[i].field.empty() ? "" : errs[i].field + " ") + errs[i].message;
    }
    return {VarResult::kInvalid, msg};
  }
  if (apply_now || v->owner == nullptr) {
    v->block->apply_param(v->param_index, value);
    return {};
  }
  if (!v->owner->post_param_write({v->block, v->param_index, value})) {
    // The shadow already holds the new value; put the previous (valid) one back.
    (void)v->block->stage_param(v->param_index, previous);
    return {VarResult::kBusy, "task '" + v->owner->name() + "' write queue is full"};
  }
  return {};
}

namespace {

template <class T>
void force_pin(const PinRef& ref, T value) {
  if (ref.dir == PinDir::kInput) {
    ref.as_input<T>()->force(value);
  } else {
    ref.as_output<T>()->force(value);
  }
}

// Calls f.template operator()<T>() with T the value type of a pin of type t.
template <class F>
auto with_value_type(PinType t, F&& f) {
  using R = decltype(f.template operator()<double>());
  switch (t) {
    case PinType::kBool: return f.template operator()<bool>();
    case PinType::kInt: return f.template operator()<std::int64_t>();
    case PinType::kReal: return f.template operator()<double>();
  }
  return R();
}

// Ends a force. `release` (the safe state's): an output gets its block's last computed value
// back at once.
template <class T>
void end_force(const PinRef& ref, bool release) {
  if (ref.dir == PinDir::kInput) {
    ref.as_input<T>()->unforce();
  } else if (release) {
    ref.as_output<T>()->release();
  } else {
    ref.as_output<T>()->unforce();
  }
}

bool pin_forced(const PinRef& ref) {
  return with_value_type(ref.type, [&ref]<class T>() {
    return ref.dir == PinDir::kInput ? ref.as_input<T>()->forced() : ref.as_output<T>()->forced();
  });
}

}  // namespace

VarStatus VariableRegistry::force(std::string_view name, double value) {
  const Variable* v = find(name);
  if (v == nullptr) {
    return {VarResult::kNotFound, "no variable '" + std::string(name) + "'"};
  }
  if (!v->is_pin()) {
    return {VarResult::kWrongKind,
            "'" + std::string(name) + "' is a parameter: parameters are written, pins forced"};
  }
  if (machine_ != nullptr) {
    const MachineState s = machine_->state();
    if (is_safe_state(s)) {
      return {VarResult::kInvalidState, "'" + std::string(name) + "': no forcing in " +
                                            std::string(to_string(s)) +
                                            " (the safe state wins over forces; reset first)"};
    }
  }
  if (!std::isfinite(value)) {
    return {VarResult::kTypeMismatch, "'" + std::string(name) + "': value must be finite"};
  }
  switch (v->pin.type) {
    case PinType::kBool:
      if (value != 0.0 && value != 1.0) {
        return {VarResult::kTypeMismatch, "'" + std::string(name) + "' is BOOL: 0 or 1"};
      }
      force_pin<bool>(v->pin, value != 0.0);
      break;
    case PinType::kInt:
      if (value != std::trunc(value) || std::abs(value) > 9.0e15) {
        return {VarResult::kTypeMismatch, "'" + std::string(name) + "' is LINT: whole number"};
      }
      force_pin<std::int64_t>(v->pin, static_cast<std::int64_t>(value));
      break;
    case PinType::kReal: force_pin<double>(v->pin, value); break;
  }
  // After the pin: a sweep that misses this force sees the flag and sweeps again next cycle.
  maybe_forced_.store(true, std::memory_order_release);
  return {};
}

std::size_t VariableRegistry::release_forces() noexcept {
  if (!maybe_forced_.exchange(false, std::memory_order_acq_rel)) {
    return 0;
  }
  std::size_t released = 0;
  for (const Variable& v : vars_) {
    if (!v.is_pin() || !pin_forced(v.pin)) {
      continue;
    }
    with_value_type(v.pin.type, [&v]<class T>() { end_force<T>(v.pin, /*release=*/true); });
    ++released;
  }
  return released;
}

VarStatus VariableRegistry::unforce(std::string_view name) {
  const Variable* v = find(name);
  if (v == nullptr) {
    return {VarResult::kNotFound, "no variable '" + std::string(name) + "'"};
  }
  if (!v->is_pin()) {
    return {VarResult::kWrongKind, "'" + std::string(name) + "' is a parameter"};
  }
  with_value_type(v->pin.type, [v]<class T>() { end_force<T>(v->pin, /*release=*/false); });
  return {};
}

std::vector<std::string> VariableRegistry::forced() const {
  std::vector<std::string> out;
  for (const Variable& v : vars_) {
    if (v.is_pin() && pin_forced(v.pin)) {
      out.push_back(v.name);
    }
  }
  return out;
}

}  // namespace edm::rt
