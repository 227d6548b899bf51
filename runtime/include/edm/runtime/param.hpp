#pragma once
// Block parameters: a plain struct per block type with defaults, a visit() that names each field
// for the loader and the variable registry, and a validate() that says what is wrong.
//
//   struct LowPassParams {
//     double tau_s{0.01};
//     void visit(ParamVisitor& v) { v.param("tau", tau_s, "s", "time constant"); }
//     std::vector<ParamError> validate() const;
//   };
//
// The loader fills the struct through a ParamVisitor (blocks never see YAML). At run time a
// parameter write is validated on a shadow copy (non-RT) and then applied by the owning task at
// the start of its next cycle (RT), see BlockWithParams.

#include <cstdint>
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

/// Static description of a parameter, for docs and listings.
struct ParamInfo {
  std::string_view unit;
  std::string_view description;
};

/// Visits the fields of a Params struct in declaration order.
class ParamVisitor {
 public:
  virtual ~ParamVisitor() = default;
  void param(std::string_view name, bool& v, std::string_view unit = {},
             std::string_view description = {}) {
    on_param(name, {ParamType::kBool, &v}, {unit, description});
  }
  void param(std::string_view name, std::int64_t& v, std::string_view unit = {},
             std::string_view description = {}) {
    on_param(name, {ParamType::kInt, &v}, {unit, description});
  }
  void param(std::string_view name, double& v, std::string_view unit = {},
             std::string_view description = {}) {
    on_param(name, {ParamType::kReal, &v}, {unit, description});
  }
  void param(std::string_view name, Duration& v, std::string_view unit = {},
             std::string_view description = {}) {
    on_param(name, {ParamType::kDuration, &v}, {unit, description});
  }
  void param(std::string_view name, std::string& v, std::string_view unit = {},
             std::string_view description = {}) {
    on_param(name, {ParamType::kString, &v}, {unit, description});
  }

 protected:
  virtual void on_param(std::string_view name, ParamRef ref, ParamInfo info) = 0;
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

/// Parameters of a block that has none.
struct NoParams {
  void visit(ParamVisitor& /*v*/) {}
  [[nodiscard]] std::vector<ParamError> validate() const { return {}; }
};

}  // namespace edm::rt
