#pragma once
// Block parameters: a plain struct per block type with defaults and one visit() that declares
// each field once — its name, unit, description, range, finiteness and whether it may change at
// run time. Validation, the refusal of a runtime write, `edmplc --list-vars` and the parameter
// tables of docs/blocks.md all come from that declaration:
//
//   struct LowPassParams {
//     double tau_s{0.01};
//     void visit(ParamVisitor& v) {
//       v.param("tau", tau_s, {"s", "time constant", kPositive});  // {unit, description, range}
//     }
//   };
//
// One row a parameter, the ParamSpec positional; load_time({…}) for a field only the config
// sets; the designated form ({.unit = …, .finite = false}) for the rest.
//
// A Params struct may add `std::vector<ParamError> validate() const` for rules that tie fields
// together (e.g. "max >= min"); it runs only once every field is in its own range.
//
// The loader fills the struct through a ParamVisitor (blocks never see YAML). At run time a
// parameter write is validated on a shadow copy (non-RT) and then applied by the owning task at
// the start of its next cycle (RT), see BlockWithParams.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "edm/runtime/time.hpp"

namespace edm::rt {

enum class ParamType : std::uint8_t { kBool, kInt, kReal, kDuration, kString };

std::string_view to_string(ParamType t) noexcept;

/// A trivially copyable parameter value (strings are load-time only and never travel as values).
struct ParamValue {
  ParamType type{ParamType::kReal};
  bool b{false};
  std::int64_t i{0};  // kInt, and kDuration in nanoseconds
  double r{0.0};

  static ParamValue of_bool(bool v) noexcept { return {ParamType::kBool, v, 0, 0.0}; }
  static ParamValue of_int(std::int64_t v) noexcept { return {ParamType::kInt, false, v, 0.0}; }
  static ParamValue of_real(double v) noexcept { return {ParamType::kReal, false, 0, v}; }
  static ParamValue of_duration(Duration v) noexcept {
    return {ParamType::kDuration, false, v.count(), 0.0};
  }
  /// The value as a double (bool → 0/1, duration → seconds).
  [[nodiscard]] double as_double() const noexcept;
};

/// One problem with a parameter: the field's YAML name and a message.
struct ParamError {
  std::string field;    // empty when the problem is not tied to one field
  std::string message;  // e.g. "must be > 0 (got -1)"
};

/// Type-erased reference to a parameter field.
struct ParamRef {
  ParamType type{ParamType::kReal};
  void* field{nullptr};
};

/// The allowed values of a numeric parameter (INT, REAL; TIME in seconds): a lower and an upper
/// bound, each open or closed; an infinite bound is no bound.
struct Range {
  double lo{-std::numeric_limits<double>::infinity()};
  double hi{std::numeric_limits<double>::infinity()};
  bool lo_open{false};
  bool hi_open{false};

  [[nodiscard]] bool contains(double v) const noexcept {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  [[nodiscard]] bool unbounded() const noexcept;
  /// Both bounds finite and lo < hi: what every runtime-writable number declares.
  [[nodiscard]] bool bounded() const noexcept;
  /// "> 0", ">= 1", "< 5", "<= 5", "[0, 1]", "(0, 1]", … ; empty when unbounded.
  [[nodiscard]] std::string text() const;
};

constexpr Range above(double lo) noexcept {
  return {lo, std::numeric_limits<double>::infinity(), true, false};
}
constexpr Range at_least(double lo) noexcept {
  return {lo, std::numeric_limits<double>::infinity(), false, false};
}
constexpr Range below(double hi) noexcept {
  return {-std::numeric_limits<double>::infinity(), hi, false, true};
}
constexpr Range at_most(double hi) noexcept {
  return {-std::numeric_limits<double>::infinity(), hi, false, false};
}
constexpr Range closed(double lo, double hi) noexcept { return {lo, hi, false, false}; }
constexpr Range open_closed(double lo, double hi) noexcept { return {lo, hi, true, false}; }
constexpr Range closed_open(double lo, double hi) noexcept { return {lo, hi, false, true}; }
constexpr Range open(double lo, double hi) noexcept { return {lo, hi, true, true}; }
inline constexpr Range kPositive = above(0.0);
inline constexpr Range kNonNegative = at_least(0.0);

/// Everything said about a parameter, declared once in the Params struct's visit().
/// A runtime-writable INT, REAL or TIME field must declare a bounded range (finite lo < hi, the
/// default inside): its physical range, so that no writer — bridge, Modbus, MQTT, config — can
/// set a value the machine cannot mean (issue 31: gap.kg took 9.2e18). SpecAudit checks this
/// for every registered type (ctest params.*, and edm_paramdoc).
struct ParamSpec {
  std::string_view unit{};         // "mm/s", "us", "" (dimensionless)
  std::string_view description{};  // one line, for listings and docs/blocks.md
  Range range{};                   // checked for INT, REAL and TIME (seconds) fields
  bool finite{true};               // REAL: NaN and ±inf are refused
  bool load_time_only{false};      // a runtime write is refused (sizes buffers, precomputed)
};
using ParamInfo = ParamSpec;  // the older name, kept for visitors outside the runtime

/// `spec` for a field that only the config sets (a runtime write is refused: it sizes a buffer,
/// or something is precomputed from it): `v.param("window", window, load_time({"samples",
/// "number of samples averaged", closed(1, 4096)}))`.
constexpr ParamSpec load_time(ParamSpec spec) noexcept {
  spec.load_time_only = true;
  return spec;
}

/// Visits the fields of a Params struct in declaration order.
class ParamVisitor {
 public:
  virtual ~ParamVisitor() = default;
  void param(std::string_view name, bool& v, const ParamSpec& spec = {}) {
    on_param(name, {ParamType::kBool, &v}, spec);
  }
  void param(std::string_view name, std::int64_t& v, const ParamSpec& spec = {}) {
    on_param(name, {ParamType::kInt, &v}, spec);
  }
  void param(std::string_view name, double& v, const ParamSpec& spec = {}) {
    on_param(name, {ParamType::kReal, &v}, spec);
  }
  void param(std::string_view name, Duration& v, const ParamSpec& spec = {}) {
    on_param(name, {ParamType::kDuration, &v}, spec);
  }
  void param(std::string_view name, std::string& v, const ParamSpec& spec = {}) {
    on_param(name, {ParamType::kString, &v}, spec);
  }
  /// The older form: unit and description only, no range. Being replaced by ParamSpec.
  template <class T>
  void param(std::string_view name, T& v, std::string_view unit,
             std::string_view description = {}) {
    param(name, v, ParamSpec{unit, description});
  }
  /// Passes on an already type-erased field (composites re-expose their children's).
  void forward(std::string_view name, ParamRef ref, const ParamSpec& spec) {
    on_param(name, ref, spec);
  }

 protected:
  virtual void on_param(std::string_view name, ParamRef ref, ParamSpec spec) = 0;
};

/// Reads a field as a value (strings give an empty kString value). RT-safe.
ParamValue read_param(const ParamRef& ref) noexcept;
/// Writes a value into a field of the same type; false on a type mismatch or a string. RT-safe.
bool write_param(const ParamRef& ref, const ParamValue& v) noexcept;

/// Helpers for validate() implementations. Range checks alone let NaN through (every comparison
/// with NaN is false), so call require_finite first for REAL parameters without a range.
void require_positive(std::vector<ParamError>& errs, std::string_view field, double v);
void require_non_negative(std::vector<ParamError>& errs, std::string_view field, double v);
void require_range(std::vector<ParamError>& errs, std::string_view field, double v, double lo,
                   double hi);
void require_finite(std::vector<ParamError>& errs, std::string_view field, double v);
/// Adds an error on hi_field unless lo <= hi (e.g. "max" must be >= "min").
void require_ordered(std::vector<ParamError>& errs, std::string_view lo_field, double lo,
                     std::string_view hi_field, double hi);

/// The problem with one field's value against its ParamSpec (range, finiteness), if any.
/// Non-RT (builds a message).
void check_field(std::vector<ParamError>& errs, std::string_view name, ParamRef ref,
                 const ParamSpec& spec);

/// Why `v` is not allowed by `spec` — a non-finite REAL, or outside the range — e.g.
/// "must be in (0, 10] (got 9.22337e18)", with_unit "must be in (0, 10] mm/s/us (got …)"; empty
/// when it is allowed (BOOL and STRING always are). TIME in seconds. Non-RT (builds a message).
std::string range_violation(const ParamSpec& spec, const ParamValue& v, bool with_unit = false);

/// True when a runtime write of a field of this type can happen: not load-time only and not a
/// STRING (strings are set in the config only). RT-safe.
constexpr bool runtime_writable(ParamType t, const ParamSpec& spec) noexcept {
  return !spec.load_time_only && t != ParamType::kString;
}
/// True when the field must declare a bounded range: a runtime-writable INT, REAL or TIME.
constexpr bool needs_range(ParamType t, const ParamSpec& spec) noexcept {
  return runtime_writable(t, spec) && t != ParamType::kBool;
}

/// Audits the declarations of a Params struct (or a block's visit_params()): every field that
/// needs_range() declares a bounded range, and the field's current value (on a default-built
/// block: its default) lies in it. One problem per bad field, naming it. Non-RT.
class SpecAudit final : public ParamVisitor {
 public:
  std::vector<ParamError> problems;
  std::size_t writable_numbers{0};  // fields seen that need a range (with or without one)

 protected:
  void on_param(std::string_view name, ParamRef ref, ParamSpec spec) override;
};

/// Checks every field of a Params struct against its ParamSpec. Non-RT.
class SpecChecker final : public ParamVisitor {
 public:
  std::vector<ParamError> errors;

 protected:
  void on_param(std::string_view name, ParamRef ref, ParamSpec spec) override {
    check_field(errors, name, ref, spec);
  }
};

/// Counts fields without allocating. RT-safe.
class ParamCounter final : public ParamVisitor {
 public:
  std::size_t count{0};

 protected:
  void on_param(std::string_view, ParamRef, ParamSpec) override { ++count; }
};

/// The field at `index` (visit order): its reference and spec. RT-safe (no allocation).
class ParamAt final : public ParamVisitor {
 public:
  explicit ParamAt(std::size_t index) noexcept : index_(index) {}
  ParamRef ref{};
  ParamSpec spec{};
  bool found{false};

 protected:
  void on_param(std::string_view, ParamRef r, ParamSpec s) override {
    if (n_++ == index_) {
      ref = r;
      spec = s;
      found = true;
    }
  }

 private:
  std::size_t index_;
  std::size_t n_{0};
};

/// A Params struct's own cross-field rules, if it declares validate(); none otherwise.
template <class P>
std::vector<ParamError> cross_field_errors(const P& p) {
  if constexpr (requires { p.validate(); }) {
    return p.validate();
  } else {
    return {};
  }
}

/// Every problem of a Params struct: each field against its spec, then (only if every field is
/// in range) the struct's cross-field rules. Non-RT.
template <class P>
std::vector<ParamError> validate_params(const P& p) {
  P copy = p;  // visit() takes non-const references
  SpecChecker c;
  copy.visit(c);
  if (!c.errors.empty()) {
    return std::move(c.errors);
  }
  return cross_field_errors(p);
}

/// Parameters of a block that has none.
struct NoParams {
  void visit(ParamVisitor& /*v*/) {}
};

}  // namespace edm::rt
