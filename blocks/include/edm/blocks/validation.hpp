#pragma once
// Checks shared by the block library's configure() implementations, on top of the runtime's
// require_positive/require_non_negative/require_range/require_finite/require_ordered.
//
// Non-RT: these build error messages (allocate). Thread-safe: pure functions.

#include <string_view>
#include <utility>
#include <vector>

#include "edm/runtime/param.hpp"
#include "edm/runtime/time.hpp"

namespace edm::blocks {

/// Adds an error unless the task period handed to configure() is > 0: blocks that discretise
/// continuous-time behaviour need a sampling interval.
void require_task_period(std::vector<rt::ParamError>& errs, rt::Duration period);
/// The same as a list of its own: for a configure() whose only check is the period.
[[nodiscard]] std::vector<rt::ParamError> task_period_errors(rt::Duration period);

/// The configure() of a block that sizes or precomputes from its parameters: checks them (each
/// field against its spec, then the cross-field rules) and runs `prepare` only if they pass.
template <class Params, class Prepare>
[[nodiscard]] std::vector<rt::ParamError> configure_checked(const Params& params,
                                                            Prepare&& prepare) {
  auto errs = rt::validate_params(params);
  if (errs.empty()) {
    std::forward<Prepare>(prepare)();
  }
  return errs;
}
/// The same for a block that also needs a task period > 0.
template <class Params, class Prepare>
[[nodiscard]] std::vector<rt::ParamError> configure_checked(const Params& params,
                                                            rt::Duration period,
                                                            Prepare&& prepare) {
  auto errs = rt::validate_params(params);
  require_task_period(errs, period);
  if (errs.empty()) {
    std::forward<Prepare>(prepare)();
  }
  return errs;
}

}  // namespace edm::blocks
