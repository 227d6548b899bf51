#pragma once
// Checks shared by the block library's configure() implementations, on top of the runtime's
// require_positive/require_non_negative/require_range/require_finite/require_ordered.
//
// Non-RT: these build error messages (allocate). Thread-safe: pure functions.

#include <string_view>
#include <vector>

#include "edm/runtime/param.hpp"
#include "edm/runtime/time.hpp"

namespace edm::blocks {

/// Adds an error unless the task period handed to configure() is > 0: blocks that discretise
/// continuous-time behaviour need a sampling interval.
void require_task_period(std::vector<rt::ParamError>& errs, rt::Duration period);
/// The same as a list of its own: for a configure() whose only check is the period.
[[nodiscard]] std::vector<rt::ParamError> task_period_errors(rt::Duration period);

}  // namespace edm::blocks
