#include "edm/programs/short_guard.hpp"

namespace edm::programs {

void ShortLimits::visit(rt::ParamVisitor& v) {
  v.param("short_ratio_limit", short_ratio_limit,
          {"", "the Td window, or one cycle alone, reads short at this fraction of shorted pulses",
           rt::open_closed(0.0, 1.0)});
  v.param("short_retracts_max", short_retracts_max,
          {"", "retracts without progress allowed within the window; one more: alarm 150",
           rt::closed(1, RetractBudget::kMaxRetracts)});
  v.param("short_retracts_window", short_retracts_window,
          {"s", "the time over which short retracts are counted", rt::open_closed(0.0, 3600.0)});
}

}  // namespace edm::programs
