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
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
  } else {
    std::snprintf(buf, sizeof buf, "%g", v);
  }
  return buf;
}
}  // namespace

bool Range::unbounded() const noexcept { return std::isinf(lo) && std::isinf(hi); }

std::string Range::text() const {
  const bool has_lo = !std::isinf(lo);
  const bool has_hi = !std::isinf(hi);
  if (has_lo && has_hi) {
    return std::string(lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
  }
  if (has_lo) {
    return (lo_open ? "> " : ">= ") + num(lo);
  }
  if (has_hi) {
    return (hi_open ? "< " : "<= ") + num(hi);
  }
  return {};
}

void check_field(std::vector<ParamError>& errs, std::string_view name, ParamRef ref,
                 const ParamSpec& spec) {
  double v = 0.0;
  switch (ref.type) {
    case ParamType::kBool:
    case ParamType::kString:
      return;
    case ParamType::kInt:
      v = static_cast<double>(*static_cast<const std::int64_t*>(ref.field));
      break;
    case ParamType::kReal:
      v = *static_cast<const double*>(ref.field);
      if (spec.finite && !std::isfinite(v)) {
        errs.push_back({std::string(name), "must be a finite number (got " + num(v) + ")"});
        return;
      }
      break;
    case ParamType::kDuration:
      v = read_param(ref).as_double();
      break;
  }
  if (!spec.range.contains(v)) {
    const std::string t = spec.range.text();
    const bool interval = !t.empty() && (t[0] == '[' || t[0] == '(');
    errs.push_back({std::string(name), std::string("must be ") + (interval ? "in " : "") + t +
                                           " (got " + num(v) + ")"});
  }
}

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
