#include "edm/blocks/validation.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace edm::blocks {
namespace {

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

void require_finite(std::vector<rt::ParamError>& errs, std::string_view field, double v) {
  if (!std::isfinite(v)) {
    errs.push_back({std::string(field), "must be a finite number (got " + format_number(v) + ")"});
  }
}

void require_ordered(std::vector<rt::ParamError>& errs, std::string_view lo_field, double lo,
                     std::string_view hi_field, double hi) {
  if (!(lo <= hi)) {
    errs.push_back({std::string(hi_field), "must be >= " + std::string(lo_field) + " (got " +
                                               format_number(hi) + " < " + format_number(lo) +
                                               ")"});
  }
}

void require_task_period(std::vector<rt::ParamError>& errs, rt::Duration period) {
  if (period.count() <= 0) {
    errs.push_back(
        {"", "needs a task with a period > 0 (got " + std::to_string(period.count()) + "ns)"});
  }
}

}  // namespace edm::blocks
