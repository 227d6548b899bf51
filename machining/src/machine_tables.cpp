#include "edm/machining/machine_tables.hpp"

#include <cmath>

namespace edm::machining {

const Condition* MachineTables::condition(int e) const noexcept {
  for (const Condition& c : conditions)
    if (c.e == e) return &c;
  return nullptr;
}

const AxisLimits* MachineTables::axis(char name) const noexcept {
  for (const AxisLimits& a : axes)
    if (a.name == name) return &a;
  return nullptr;
}

double* condition_field(Condition& c, std::string_view field) noexcept {
  if (field == "open_voltage_v") return &c.open_voltage_v;
  if (field == "peak_current_a") return &c.peak_current_a;
  if (field == "on_time_us") return &c.on_time_us;
  if (field == "off_time_us") return &c.off_time_us;
  if (field == "tdr_us") return &c.tdr_us;
  if (field == "servo_ref_v") return &c.servo_ref_v;
  if (field == "wear_ratio") return &c.wear_ratio;
  if (field == "area_ratio") return &c.area_ratio;
  if (field == "offset_mm") return &c.offset_mm;
  return nullptr;
}

std::optional<std::string> condition_value_error(std::string_view field, double value) {
  Condition probe;
  if (condition_field(probe, field) == nullptr) {
    return "'" + std::string(field) + "' is no numeric field of a condition";
  }
  const std::string got = " (got " + std::to_string(value) + ")";
  if (!std::isfinite(value)) return std::string(field) + " must be a finite number";
  if (field == "wear_ratio") {
    if (value < 0.0 || value > 10.0) return "wear_ratio must be in 0..10" + got;
  } else if (field == "area_ratio") {
    if (!(value > 0.0 && value <= 100.0)) return "area_ratio must be in (0, 100]" + got;
  } else if (field == "offset_mm") {
    if (value < 0.0 || value > 10.0) return "offset_mm must be in 0..10" + got;
  } else if (!(value > 0.0)) {
    return std::string(field) + " must be > 0" + got;
  }
  return std::nullopt;
}

std::string_view to_string(MachineKind k) noexcept {
  switch (k) {
    case MachineKind::kDrill: return "drill";
    case MachineKind::kWire: return "wire";
    case MachineKind::kSink: return "sink";
  }
  return "drill";
}

bool machine_kind_from_string(std::string_view s, MachineKind& out) noexcept {
  for (MachineKind k : {MachineKind::kDrill, MachineKind::kWire, MachineKind::kSink}) {
    if (s == to_string(k)) {
      out = k;
      return true;
    }
  }
  return false;
}

MachineTables make_tables(const std::vector<LocatedAxis>& axes,
                          const std::vector<LocatedCondition>& conditions, MachineKind kind) {
  MachineTables t;
  t.kind = kind;
  t.axes.assign(axes.begin(), axes.end());
  t.conditions.assign(conditions.begin(), conditions.end());
  return t;
}

}  // namespace edm::machining
