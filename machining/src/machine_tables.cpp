#include "edm/machining/machine_tables.hpp"

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

MachineTables make_tables(const std::vector<LocatedAxis>& axes,
                          const std::vector<LocatedCondition>& conditions) {
  MachineTables t;
  t.axes.assign(axes.begin(), axes.end());
  t.conditions.assign(conditions.begin(), conditions.end());
  return t;
}

}  // namespace edm::machining
