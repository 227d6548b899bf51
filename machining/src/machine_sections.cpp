// machine.axes and conditions of a machine config: the one reader both the runtime and the HMI
// use. See machine_sections.hpp.

#include "edm/machining/machine_sections.hpp"

#include <climits>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>

namespace edm::machining {

namespace {

using yaml::Field;
using yaml::MapView;
using yaml::Value;

/// First place each name (axis letter, E number) was written.
class FirstSeen {
 public:
  /// The line of the first occurrence if `name` was seen before, else nullopt.
  std::optional<int> add(const std::string& name, const SourceLoc& loc) {
    const auto [it, inserted] = first_line_.emplace(name, loc.line);
    return inserted ? std::nullopt : std::optional<int>(it->second);
  }

 private:
  std::unordered_map<std::string, int> first_line_;
};

void positive(yaml::Reader& r, const MapView& m, std::string_view key, double& out) {
  if (const Field* f = m.find(key)) {
    if (auto x = r.real(f->value)) {
      if (*x <= 0.0) {
        r.error(f->value, "must be > 0 (got " + f->value.node.Scalar() + ")");
      } else {
        out = *x;
      }
    }
  }
}

/// One axis; returns its name (nullopt when unreadable) and where the name was written.
std::optional<char> read_axis(yaml::Reader& r, const Value& v, LocatedAxis& out,
                              SourceLoc& name_loc) {
  out.loc = v.loc;
  name_loc = v.loc;
  auto m = r.map(v, {"name", "min_mm", "max_mm", "v_max_mm_s", "a_max_mm_s2"});
  if (!m) {
    return std::nullopt;
  }
  std::optional<char> name;
  if (const Field* f = r.require(*m, "name")) {
    name_loc = f->value.loc;
    if (auto s = r.choice(f->value, {"X", "Y", "Z"})) {
      name = (*s)[0];
      out.name = *name;
    }
  }
  std::optional<double> min_mm;
  std::optional<double> max_mm;
  if (const Field* f = r.require(*m, "min_mm")) {
    min_mm = r.real(f->value);
  }
  const Field* max_field = r.require(*m, "max_mm");
  if (max_field != nullptr) {
    max_mm = r.real(max_field->value);
  }
  if (min_mm && max_mm && *max_mm <= *min_mm) {
    r.error(max_field->value, "must be > min_mm (got max_mm " + max_field->value.node.Scalar() +
                                  " <= min_mm " + m->find("min_mm")->value.node.Scalar() + ")");
  }
  out.min_mm = min_mm.value_or(out.min_mm);
  out.max_mm = max_mm.value_or(out.max_mm);
  positive(r, *m, "v_max_mm_s", out.v_max_mm_s);
  positive(r, *m, "a_max_mm_s2", out.a_max_mm_s2);
  return name;
}

/// One condition; returns where its E number was written.
SourceLoc read_condition(yaml::Reader& r, const Value& v, LocatedCondition& out) {
  out.loc = v.loc;
  SourceLoc e_loc = v.loc;
  auto m =
      r.map(v, {"E", "name", "polarity", "open_voltage_v", "peak_current_a", "on_time_us",
                "off_time_us", "tdr_us", "servo_ref_v", "wear_ratio", "area_ratio", "offset_mm"});
  if (!m) {
    return e_loc;
  }
  if (const Field* f = r.require(*m, "E")) {
    e_loc = f->value.loc;
    out.e = static_cast<int>(r.integer(f->value, 1, INT_MAX).value_or(0));
  }
  if (const Field* f = m->find("name")) {
    out.name = r.string(f->value).value_or("");
  }
  if (const Field* f = m->find("polarity")) {
    if (auto s = r.choice(f->value, {"negative", "positive"})) {
      out.polarity = *s == "positive" ? Polarity::kPositive : Polarity::kNegative;
    }
  }
  positive(r, *m, "open_voltage_v", out.open_voltage_v);
  positive(r, *m, "peak_current_a", out.peak_current_a);
  positive(r, *m, "on_time_us", out.on_time_us);
  positive(r, *m, "off_time_us", out.off_time_us);
  positive(r, *m, "tdr_us", out.tdr_us);
  positive(r, *m, "servo_ref_v", out.servo_ref_v);
  if (const Field* f = m->find("wear_ratio")) {
    if (auto x = r.real(f->value)) {
      if (*x < 0.0 || *x > 10.0) {
        r.error(f->value, "must be in 0..10 (got " + f->value.node.Scalar() + ")");
      } else {
        out.wear_ratio = *x;
      }
    }
  }
  if (const Field* f = m->find("offset_mm")) {
    if (auto x = r.real(f->value)) {
      if (*x < 0.0 || *x > 10.0) {
        r.error(f->value, "must be in 0..10 mm (got " + f->value.node.Scalar() + ")");
      } else {
        out.offset_mm = *x;
      }
    }
  }
  if (const Field* f = m->find("area_ratio")) {
    if (auto x = r.real(f->value)) {
      if (!(*x > 0.0 && *x <= 100.0)) {
        r.error(f->value, "must be in (0, 100] (got " + f->value.node.Scalar() + ")");
      } else {
        out.area_ratio = *x;
      }
    }
  }
  return e_loc;
}

/// What makes a list item unique: its key, where it was written, and how an error names it.
struct ItemKey {
  std::string key;
  SourceLoc loc;
  const char* field;  // appended to the item's path
  std::string label;  // "axis 'X'", "condition E3"
};

/// Reads each item of a list with read_one(item, out) -> optional<ItemKey>; a key written twice is
/// an error "duplicate <label> (first at line L)".
template <class T, class ReadOne>
std::vector<T> read_keyed_list(yaml::Reader& r, const Value& list, ReadOne read_one) {
  std::vector<T> out;
  auto items = r.list(list);
  if (!items) {
    return out;
  }
  FirstSeen seen;
  for (const Value& item : *items) {
    T t;
    if (const std::optional<ItemKey> k = read_one(item, t)) {
      if (const std::optional<int> first = seen.add(k->key, k->loc)) {
        r.error(k->loc, item.path + k->field,
                "duplicate " + k->label + " (first at line " + std::to_string(*first) + ")");
      }
    }
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace

MachineKind read_machine_kind(yaml::Reader& r, const Value& v) {
  MachineKind k = MachineKind::kDrill;
  if (auto s = r.choice(v, {"drill", "wire", "sink"})) machine_kind_from_string(*s, k);
  return k;
}

std::vector<LocatedAxis> read_axes(yaml::Reader& r, const Value& axes) {
  return read_keyed_list<LocatedAxis>(r, axes, [&r](const Value& item, LocatedAxis& a) {
    SourceLoc name_loc;
    const std::optional<char> name = read_axis(r, item, a, name_loc);
    return name ? std::optional<ItemKey>({std::string(1, *name), name_loc, ".name",
                                          "axis '" + std::string(1, *name) + "'"})
                : std::nullopt;
  });
}

std::vector<LocatedCondition> read_conditions(yaml::Reader& r, const Value& conditions) {
  const auto read_one = [&r](const Value& item, LocatedCondition& c) {
    const SourceLoc e_loc = read_condition(r, item, c);
    const std::string e = std::to_string(c.e);
    return c.e >= 1 ? std::optional<ItemKey>({e, e_loc, ".E", "condition E" + e}) : std::nullopt;
  };
  return read_keyed_list<LocatedCondition>(r, conditions, read_one);
}

}  // namespace edm::machining
