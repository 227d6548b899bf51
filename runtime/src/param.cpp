#include "edm/runtime/param.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace edm::rt {

std::string_view to_string(ParamType t) noexcept {
  switch (t) {
    case ParamType::kBool: return "BOOL";
    case ParamType::kInt: return "LINT";
    case ParamType::kReal: return "LREAL";
    case ParamType::kDuration: return "TIME";
    case ParamType::kString: return "STRING";
  }
  return "?";
}

double ParamValue::as_double() const noexcept {
  switch (type) {
    case ParamType::kBool: return b ? 1.0 : 0.0;
    case ParamType::kInt: return static_cast<double>(i);
    case ParamType::kReal: return r;
    case ParamType::kDuration:
      return static_cast<double>(i) / 1e9;  // exact for whole seconds: 60 s is 60, not 60.00…01
    case ParamType::kString: return 0.0;
  }
  return 0.0;
}

ParamValue read_param(const ParamRef& ref) noexcept {
  switch (ref.type) {
    case ParamType::kBool: return ParamValue::of_bool(*static_cast<bool*>(ref.field));
    case ParamType::kInt: return ParamValue::of_int(*static_cast<std::int64_t*>(ref.field));
    case ParamType::kReal: return ParamValue::of_real(*static_cast<double*>(ref.field));
    case ParamType::kDuration: return ParamValue::of_duration(*static_cast<Duration*>(ref.field));
    case ParamType::kString: break;
  }
  return ParamValue{ParamType::kString, false, 0, 0.0};
}

bool write_param(const ParamRef& ref, const ParamValue& v) noexcept {
  if (ref.type != v.type || ref.field == nullptr) {
    return false;
  }
  switch (ref.type) {
    case ParamType::kBool: *static_cast<bool*>(ref.field) = v.b; return true;
    case ParamType::kInt: *static_cast<std::int64_t*>(ref.field) = v.i; return true;
    case ParamType::kReal: *static_cast<double*>(ref.field) = v.r; return true;
    case ParamType::kDuration: *static_cast<Duration*>(ref.field) = Duration{v.i}; return true;
    case ParamType::kString: return false;
  }
  return false;
}

namespace {
// Whole numbers in full up to a million, everything else as %g with the exponent trimmed:
// "65536", "0.05", "1e9", "-1e12", "9.22337e18".
std::string num(double v) {
  char buf[64];
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e6) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
  }
  std::snprintf(buf, sizeof buf, "%g", v);
  std::string s = buf;
  if (const std::size_t e = s.find('e'); e != std::string::npos) {
    std::size_t d = e + 1;
    if (s[d] == '+') {
      s.erase(d, 1);
    } else if (s[d] == '-') {
      ++d;
    }
    while (d + 1 < s.size() && s[d] == '0') {
      s.erase(d, 1);
    }
  }
  return s;
}

// The message check_field and range_violation give for a value outside the range, e.g.
// "must be in (0, 10] (got 20)" or, with the unit, "must be in (0, 10] mm/s/us (got 20)".
std::string outside(const Range& r, double v, std::string_view unit = {}) {
  const std::string t = r.text();
  const bool interval = !t.empty() && (t[0] == '[' || t[0] == '(');
  return std::string("must be ") + (interval ? "in " : "") + t +
         (unit.empty() ? "" : " " + std::string(unit)) + " (got " + num(v) + ")";
}
}  // namespace

bool Range::unbounded() const noexcept { return std::isinf(lo) && std::isinf(hi); }

bool Range::bounded() const noexcept { return std::isfinite(lo) && std::isfinite(hi) && lo < hi; }

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
    case ParamType::kString: return;
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
    case ParamType::kDuration: v = read_param(ref).as_double(); break;
  }
  if (!spec.range.contains(v)) {
    errs.push_back({std::string(name), outside(spec.range, v)});
  }
}

std::string range_violation(const ParamSpec& spec, const ParamValue& v, bool with_unit) {
  switch (v.type) {
    case ParamType::kBool:
    case ParamType::kString: return {};
    case ParamType::kReal:
      if (spec.finite && !std::isfinite(v.r)) {
        return "must be a finite number (got " + num(v.r) + ")";
      }
      break;
    case ParamType::kInt:
    case ParamType::kDuration: break;
  }
  const double x = v.as_double();
  return spec.range.contains(x)
             ? std::string()
             : outside(spec.range, x, with_unit ? spec.unit : std::string_view{});
}

void SpecAudit::on_param(std::string_view name, ParamRef ref, ParamSpec spec) {
  if (!needs_range(ref.type, spec)) {
    return;
  }
  ++writable_numbers;
  const std::string type(to_string(ref.type));
  if (!spec.range.bounded()) {
    const std::string t = spec.range.text();
    problems.push_back(
        {std::string(name), "is a runtime-writable " + type + " without a bounded range (" +
                                (t.empty() ? std::string("none") : t) +
                                "): declare its physical [min, max], or load_time_only"});
    return;
  }
  if (const std::string why = range_violation(spec, read_param(ref)); !why.empty()) {
    problems.push_back({std::string(name), "default outside its own range: " + why});
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
