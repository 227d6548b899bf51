#include "edm/bridge/machine_info.hpp"

#include <cmath>
#include <set>

namespace edm::bridge {

namespace {

using machining::AxisLimits;
using machining::Condition;
using machining::Polarity;

bool get_number(const Json& o, const char* key, double& out, std::string& error,
                const std::string& where) {
  const auto it = o.find(key);
  if (it == o.end() || !it->is_number() || !std::isfinite(it->get<double>())) {
    error = where + "." + key + ": a finite number is required";
    return false;
  }
  out = it->get<double>();
  return true;
}

bool get_string(const Json& o, const char* key, std::string& out, std::string& error,
                const std::string& where) {
  const auto it = o.find(key);
  if (it == o.end() || !it->is_string()) {
    error = where + "." + key + ": a string is required";
    return false;
  }
  out = it->get<std::string>();
  return true;
}

// Optional: absent from an older runtime's reply, it is the paper's single A (1).
bool area_ratio_from_json(const Json& j, Condition& c, std::string& error,
                          const std::string& where) {
  if (!j.contains("area_ratio")) return true;
  if (!get_number(j, "area_ratio", c.area_ratio, error, where)) return false;
  if (!(c.area_ratio > 0.0 && c.area_ratio <= 100.0)) {
    error = where + ".area_ratio: must be in (0, 100]";
    return false;
  }
  return true;
}

bool offset_from_json(const Json& j, Condition& c, std::string& error, const std::string& where) {
  if (!j.contains("offset_mm")) return true;
  if (!get_number(j, "offset_mm", c.offset_mm, error, where)) return false;
  if (!(c.offset_mm >= 0.0 && c.offset_mm <= 10.0)) {
    error = where + ".offset_mm: must be in 0..10";
    return false;
  }
  return true;
}

bool axis_from_json(const Json& j, AxisLimits& a, std::string& error, const std::string& where) {
  if (!j.is_object()) {
    error = where + ": an object is required";
    return false;
  }
  std::string name;
  if (!get_string(j, "name", name, error, where)) return false;
  if (name != "X" && name != "Y" && name != "Z") {
    error = where + ".name: 'X', 'Y' or 'Z' expected, got '" + name + "'";
    return false;
  }
  a.name = name[0];
  if (!get_number(j, "min_mm", a.min_mm, error, where) ||
      !get_number(j, "max_mm", a.max_mm, error, where) ||
      !get_number(j, "v_max_mm_s", a.v_max_mm_s, error, where) ||
      !get_number(j, "a_max_mm_s2", a.a_max_mm_s2, error, where)) {
    return false;
  }
  if (a.min_mm > a.max_mm) {
    error = where + ": min_mm > max_mm";
    return false;
  }
  return true;
}

bool condition_from_json(const Json& j, Condition& c, std::string& error,
                         const std::string& where) {
  if (!j.is_object()) {
    error = where + ": an object is required";
    return false;
  }
  const auto e = j.find("E");
  if (e == j.end() || !e->is_number_integer() || e->get<std::int64_t>() < 1 ||
      e->get<std::int64_t>() > 1'000'000) {
    error = where + ".E: an integer >= 1 is required";
    return false;
  }
  c.e = static_cast<int>(e->get<std::int64_t>());
  std::string polarity;
  if (!get_string(j, "name", c.name, error, where) ||
      !get_string(j, "polarity", polarity, error, where)) {
    return false;
  }
  if (polarity != "negative" && polarity != "positive") {
    error = where + ".polarity: 'negative' or 'positive' expected";
    return false;
  }
  c.polarity = polarity == "positive" ? Polarity::kPositive : Polarity::kNegative;
  return get_number(j, "open_voltage_v", c.open_voltage_v, error, where) &&
         get_number(j, "peak_current_a", c.peak_current_a, error, where) &&
         get_number(j, "on_time_us", c.on_time_us, error, where) &&
         get_number(j, "off_time_us", c.off_time_us, error, where) &&
         get_number(j, "tdr_us", c.tdr_us, error, where) &&
         get_number(j, "servo_ref_v", c.servo_ref_v, error, where) &&
         get_number(j, "wear_ratio", c.wear_ratio, error, where) &&
         area_ratio_from_json(j, c, error, where) && offset_from_json(j, c, error, where);
}

}  // namespace

Json to_json(const machining::MachineTables& tables, const std::string& machine_name) {
  Json axes = Json::array();
  for (const AxisLimits& a : tables.axes) {
    axes.push_back({{"name", std::string(1, a.name)},
                    {"min_mm", a.min_mm},
                    {"max_mm", a.max_mm},
                    {"v_max_mm_s", a.v_max_mm_s},
                    {"a_max_mm_s2", a.a_max_mm_s2}});
  }
  Json conditions = Json::array();
  for (const Condition& c : tables.conditions) {
    conditions.push_back({{"E", c.e},
                          {"name", c.name},
                          {"polarity", c.polarity == Polarity::kPositive ? "positive" : "negative"},
                          {"open_voltage_v", c.open_voltage_v},
                          {"peak_current_a", c.peak_current_a},
                          {"on_time_us", c.on_time_us},
                          {"off_time_us", c.off_time_us},
                          {"tdr_us", c.tdr_us},
                          {"servo_ref_v", c.servo_ref_v},
                          {"wear_ratio", c.wear_ratio},
                          {"area_ratio", c.area_ratio},
                          {"offset_mm", c.offset_mm}});
  }
  return Json{{"name", machine_name},
              {"kind", std::string(machining::to_string(tables.kind))},
              {"axes", axes},
              {"conditions", conditions}};
}

bool from_json(const Json& j, machining::MachineTables& out, std::string& machine_name,
               std::string& error) {
  if (!j.is_object()) {
    error = "machine.info: an object is required";
    return false;
  }
  if (!get_string(j, "name", machine_name, error, "machine")) return false;
  const auto axes = j.find("axes");
  const auto conditions = j.find("conditions");
  if (axes == j.end() || !axes->is_array() || conditions == j.end() || !conditions->is_array()) {
    error = "machine.info: 'axes' and 'conditions' arrays are required";
    return false;
  }
  machining::MachineTables t;
  if (const auto kind = j.find("kind"); kind != j.end()) {  // absent: an older runtime, a drill
    if (!kind->is_string() ||
        !machining::machine_kind_from_string(kind->get<std::string>(), t.kind)) {
      error = "machine.kind: 'drill', 'wire' or 'sink' expected";
      return false;
    }
  }
  std::set<char> axis_names;
  for (std::size_t i = 0; i < axes->size(); ++i) {
    AxisLimits a;
    if (!axis_from_json((*axes)[i], a, error, "axes[" + std::to_string(i) + "]")) return false;
    if (!axis_names.insert(a.name).second) {
      error = "axes[" + std::to_string(i) + "]: axis " + std::string(1, a.name) + " twice";
      return false;
    }
    t.axes.push_back(a);
  }
  std::set<int> e_numbers;
  for (std::size_t i = 0; i < conditions->size(); ++i) {
    Condition c;
    const std::string where = "conditions[" + std::to_string(i) + "]";
    if (!condition_from_json((*conditions)[i], c, error, where)) return false;
    if (!e_numbers.insert(c.e).second) {
      error = where + ": E" + std::to_string(c.e) + " twice";
      return false;
    }
    t.conditions.push_back(std::move(c));
  }
  out = std::move(t);
  return true;
}

}  // namespace edm::bridge
