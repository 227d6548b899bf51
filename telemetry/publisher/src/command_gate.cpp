#include "edm/telemetry/command_gate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <variant>

#include "edm/runtime/log_escape.hpp"

namespace edm::telemetry {

namespace {

namespace sp = sparkplug;

// Integers a double holds exactly (an LREAL, a TIME in seconds, the registry's numbers).
constexpr std::int64_t kExact = std::int64_t{1} << 53;
// TIME in seconds, as the registry takes it (its nanoseconds fit an int64).
constexpr double kMaxSeconds = 9.0e9;

std::string sent(const sp::Metric& m) {
  const std::string type(sp::to_string(m.type));
  const bool vowel = type.front() == 'I' || type.front() == 'U';  // Int…, UInt…, Unknown
  return (vowel ? "an " : "a ") + type + " of " +
         (std::holds_alternative<std::string>(m.value)
              ? rt::log_quote(std::get<std::string>(m.value), 40)
              : sp::to_text(m.value));
}

std::optional<rt::ParamValue> refuse(std::string& why, std::string text) {
  why = std::move(text);
  return std::nullopt;
}

std::optional<rt::ParamValue> from_seconds(double s, const sp::Metric& m, std::string& why) {
  if (!(s >= 0.0 && s <= kMaxSeconds)) {
    return refuse(why, sent(m) + " does not fit TIME (seconds in [0, 9e9])");
  }
  return rt::ParamValue::of_duration(rt::Duration{std::llround(s * 1e9)});
}

// An integer (signed or not) into `type`, checked before any conversion.
template <class Int>
std::optional<rt::ParamValue> from_integer(Int i, const sp::Metric& m, rt::ParamType type,
                                           std::string& why) {
  bool negative = false;
  auto magnitude = static_cast<std::uint64_t>(i);
  if constexpr (std::is_signed_v<Int>) {
    negative = i < 0;
    if (negative) magnitude = static_cast<std::uint64_t>(-(i + 1)) + 1;  // |INT64_MIN| too
  }
  switch (type) {
    case rt::ParamType::kBool:
      if (negative || magnitude > 1) return refuse(why, sent(m) + " does not fit BOOL (0 or 1)");
      return rt::ParamValue::of_bool(magnitude == 1);
    case rt::ParamType::kInt:
      if (!negative &&
          magnitude > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
        return refuse(why, sent(m) + " does not fit LINT (at most 2^63-1)");
      }
      return rt::ParamValue::of_int(static_cast<std::int64_t>(i));
    case rt::ParamType::kReal:
    case rt::ParamType::kDuration:
      if (magnitude > static_cast<std::uint64_t>(kExact)) {
        return refuse(why, sent(m) + " is not exact as " + std::string(rt::to_string(type)) +
                               " (integers within +-2^53 only)");
      }
      if (type == rt::ParamType::kReal) {
        return rt::ParamValue::of_real(static_cast<double>(i));
      }
      return from_seconds(static_cast<double>(i), m, why);
    case rt::ParamType::kString: break;
  }
  return refuse(why, "STRING parameters are set in the config only");
}

}  // namespace

std::optional<rt::ParamValue> command_value(const sp::Metric& m, rt::ParamType type,
                                            std::string& why) {
  const std::string target(rt::to_string(type));
  if (!m.value_ok) {
    return refuse(why, "the value does not match its datatype " +
                           std::string(sp::to_string(m.type)) + " (datatype " +
                           std::to_string(static_cast<std::uint32_t>(m.type)) +
                           "; its wire field or range)");
  }
  if (std::holds_alternative<std::monostate>(m.value)) return refuse(why, "a null value");
  if (type == rt::ParamType::kString) {
    return refuse(why, "STRING parameters are set in the config only");
  }
  if (const auto* b = std::get_if<bool>(&m.value)) {
    if (type != rt::ParamType::kBool) return refuse(why, sent(m) + " does not fit " + target);
    return rt::ParamValue::of_bool(*b);
  }
  if (const auto* i = std::get_if<std::int64_t>(&m.value)) return from_integer(*i, m, type, why);
  if (const auto* u = std::get_if<std::uint64_t>(&m.value)) return from_integer(*u, m, type, why);
  if (const auto* d = std::get_if<double>(&m.value)) {
    const double x = *d;
    if (!std::isfinite(x)) return refuse(why, sent(m) + ": the value must be finite");
    switch (type) {
      case rt::ParamType::kBool: return refuse(why, sent(m) + " does not fit BOOL: send a Boolean");
      case rt::ParamType::kInt:
        if (x != std::trunc(x) || std::fabs(x) > static_cast<double>(kExact)) {
          return refuse(why, sent(m) + " does not fit LINT (whole numbers within +-2^53)");
        }
        return rt::ParamValue::of_int(static_cast<std::int64_t>(x));
      case rt::ParamType::kReal: return rt::ParamValue::of_real(x);
      case rt::ParamType::kDuration: return from_seconds(x, m, why);
      case rt::ParamType::kString: break;
    }
  }
  return refuse(why, sent(m) + " does not fit " + target);
}

CommandOutcome CommandGate::apply(const sp::Metric& m, std::string& why) {
  if (!enabled_) {
    why = "commands are off (mqtt.commands.enabled: false)";
    return CommandOutcome::kRefused;
  }
  if (std::find(writable_.begin(), writable_.end(), m.name) == writable_.end()) {
    why = rt::log_quote(m.name) + " is not in mqtt.commands.writable";
    return CommandOutcome::kRefused;
  }
  const rt::Variable* v = vars_.find(m.name);
  if (v == nullptr || v->is_pin()) {  // the config check makes this impossible; say so anyway
    why = rt::log_quote(m.name) + " is not a parameter";
    return CommandOutcome::kRefused;
  }
  const auto value = command_value(m, v->param_type, why);
  if (!value) {
    why = "'" + v->name + "' is " + std::string(rt::to_string(v->param_type)) + ": " + why;
    return CommandOutcome::kOutOfRange;
  }
  // The registry's write: the entry point of every source (bridge, Modbus, MQTT).
  const rt::VarStatus st = vars_.write(v->name, *value);
  if (st) return CommandOutcome::kWritten;
  why = st.message.empty() ? "refused by the runtime" : st.message;
  return st.result == rt::VarResult::kInvalid || st.result == rt::VarResult::kTypeMismatch
             ? CommandOutcome::kOutOfRange
             : CommandOutcome::kRefused;
}

}  // namespace edm::telemetry
