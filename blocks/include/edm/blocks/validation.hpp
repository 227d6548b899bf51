#pragma once
// Checks shared by the block library's validate() and configure() implementations, on top of the
// runtime's require_positive/require_non_negative/require_range.
//
// Non-RT: these build error messages (allocate). Thread-safe: pure functions.

#include <string_view>
#include <vector>

#include "edm/runtime/param.hpp"
#include "edm/runtime/time.hpp"

namespace edm::blocks {

/// Adds an error if v is NaN or infinite. Range checks alone let NaN through (every comparison
/// with NaN is false), so blocks call this first for every REAL parameter.
void require_finite(std::vector<rt::ParamError>& errs, std::string_view field, double v);

/// Adds an error on hi_field unless lo ≤ hi (e.g. "max" must be ≥ "min").
void require_ordered(std::vector<rt::ParamError>& errs, std::string_view lo_field, double lo,
                     std::string_view hi_field, double hi);

/// Adds an error unless the task period handed to configure() is > 0: blocks that discretise
/// continuous-time behaviour need a sampling interval.
void require_task_period(std::vector<rt::ParamError>& errs, rt::Duration period);

/// A duration in seconds, correctly rounded (count / 1e9 rather than count · 1e-9, so that 1 ms
/// gives exactly the double nearest 0.001). RT-safe.
constexpr double seconds_of(rt::Duration d) noexcept {
  return static_cast<double>(d.count()) / 1e9;
}

}  // namespace edm::blocks
