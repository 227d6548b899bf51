#include "edm/blocks/gap_controller_p.hpp"

#include <algorithm>
#include <cmath>

namespace edm::blocks {

std::vector<rt::ParamError> GapControllerPParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_range(errs, "idle_feed_mm_s", idle_feed_mm_s, -v_feed_max_mm_s, 0.0);
  if (errs.empty()) {
    rt::require_ordered(errs, "retract_speed_mm_s", retract_speed_mm_s, "v_retract_max_mm_s",
                        v_retract_max_mm_s);
  }
  return errs;
}

void GapControllerP::activate() noexcept {
  vz_mm_s.set(0.0);
  saturated.set(false);
}

rt::BlockStatus GapControllerP::update(const rt::CycleContext& /*ctx*/) noexcept {
  const auto& p = params_;
  if (retract.get()) {
    // Validated retract_speed ≤ v_retract_max; the limit guards a direct set_params().
    vz_mm_s.set(std::min(p.retract_speed_mm_s, p.v_retract_max_mm_s));
    saturated.set(false);
    return rt::BlockStatus::kOk;
  }
  if (!enable.get() || hold.get()) {
    vz_mm_s.set(0.0);
    saturated.set(false);
    return rt::BlockStatus::kOk;
  }
  double vz = p.idle_feed_mm_s;
  if (valid.get()) {
    const double td = td_us.get();
    const double tdr_in = tdr_us.get();
    if (!std::isfinite(td) || !std::isfinite(tdr_in) || tdr_in < 0.0) {
      return rt::BlockStatus::kFault;
    }
    const double tdr = tdr_in > 0.0 ? tdr_in : p.tdr_default_us;
    vz = p.kg * (tdr - td);
    if (!std::isfinite(vz)) {  // finite inputs, but kg·error overflowed
      return rt::BlockStatus::kFault;
    }
  }
  // max/min rather than std::clamp: no undefined behaviour for limits that bypassed validate().
  const double limited = std::min(std::max(vz, -p.v_feed_max_mm_s), p.v_retract_max_mm_s);
  const bool saturated_now = limited != vz;
  vz_mm_s.set(limited);
  saturated.set(saturated_now);
  return saturated_now ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
