#include "edm/blocks/validation.hpp"

#include <string>

namespace edm::blocks {
void require_task_period(std::vector<rt::ParamError>& errs, rt::Duration period) {
  if (period.count() <= 0) {
    errs.push_back(
        {"", "needs a task with a period > 0 (got " + std::to_string(period.count()) + "ns)"});
  }
}

std::vector<rt::ParamError> task_period_errors(rt::Duration period) {
  std::vector<rt::ParamError> errs;
  require_task_period(errs, period);
  return errs;
}

}  // namespace edm::blocks
