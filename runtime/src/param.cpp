#include "edm/runtime/param.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace edm::rt {

std::string_view to_string(ParamType t) noexcept {
  switch (t) {
    case ParamType::kBool:
      return "BOOL";
    case ParamType::kInt:
      return "LINT";
    case ParamType::kReal:
      return "LREAL";
    case ParamType::kDuration:
      return "TIME";
    case ParamType::kString:
      return "STRING";
  }
  return "?";
}

double ParamValue::as_double() const noexcept {
  switch (type) {
    case ParamType::kBool:
      return b ? 1.0 : 0.0;
    case ParamType::kInt:
      return static_cast<double>(i);
    case ParamType::kReal:
      return r;
    case ParamType::kDuration:
      return static_cast<double>(i) * 1e-9;
    case ParamType::kString:
      return 0.0;
  }
  return 0.0;
}

ParamValue read_param(const ParamRef& ref) noexcept {
  switch (ref.type) {
    case ParamType::kBool:
      return ParamValue::of_bool(*static_cast<bool*>(ref.field));
    case ParamType::kInt:
      return ParamValue::of_int(*static_cast<std::int64_t*>(ref.field));
    case ParamType::kReal:
      return ParamValue::of_real(*static_cast<double*>(ref.field));
    case ParamType::kDuration:
      return ParamValue::of_duration(*static_cast<Duration*>(ref.field));
    case ParamType::kString:
      break;
  }
  return ParamValue{ParamType::kString, false, 0, 0.0};
}

bool write_param(const ParamRef& ref, const ParamValue& v) noexcept {
  if (ref.type != v.type || ref.field == nullptr) {
    return false;
  }
  switch (ref.type) {
    case ParamType::kBool:
      *static_cast<bool*>(ref.field) = v.b;
      return true;
    case ParamType::kInt:
      *static_cast<std::int64_t*>(ref.field) = v.i;
      return true;
    case ParamType::kReal:
      *static_cast<double*>(ref.field) = v.r;
      return true;
    case ParamType::kDuration:
      *static_cast<Duration*>(ref.field) = Duration{v.i};
      return true;
    case ParamType::kString:
      return false;
  }
  return false;
}

namespace {
std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
}  // namespace

void require_positive(std::vector<ParamError>& errs, std::string_view field, double v) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    errs.push_back({std::string(field), "must be > 0 (got " + num(v) + ")"});
  }
}

void require_non_negative(std::vector<ParamError>& errs, std::string_view field, double v) {
  if (!(v >= 0.0) || !std::isfinite(v)) {
    errs.push_back({std::string(field), "must be >= 0 (got " + num(v) + ")"});
  }
}

void require_range(std::vector<ParamError>& errs, std::string_view field, double v, double lo,
                   double hi) {
  if (!(v >= lo && v <= hi)) {
    errs.push_back(
        {std::string(field), "must be in [" + num(lo) + ", " + num(hi) + "] (got " + num(v) + ")"});
  }
}

void require_finite(std::vector<ParamError>& errs, std::string_view field, double v) {
  if (!std::isfinite(v)) {
    errs.push_back({std::string(field), "must be a finite number (got " + num(v) + ")"});
  }
}

void require_ordered(std::vector<ParamError>& errs, std::string_view lo_field, double lo,
                     std::string_view hi_field, double hi) {
  if (!(lo <= hi)) {
    errs.push_back({std::string(hi_field), "must be >= " + std::string(lo_field) + " (got " +
                                               num(hi) + " < " + num(lo) + ")"});
  }
}

}  // namespace edm::rt
