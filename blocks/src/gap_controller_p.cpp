#include "edm/blocks/gap_controller_p.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

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

std::vector<rt::ParamError> GapControllerP::configure(const rt::BlockSetup& setup) {
  std::vector<rt::ParamError> errs;
  require_task_period(errs, setup.period);
  dt_s_ = rt::to_seconds(setup.period);
  return errs;
}

void GapControllerP::activate() noexcept {
  vz_mm_s.set(0.0);
  saturated.set(false);
  integral_us_s_ = 0.0;
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
  double error_us = 0.0;  // Tdr − Td while the P law runs
  const bool law = valid.get();
  if (law) {
    const double td = td_us.get();
    const double tdr_in = tdr_us.get();
    if (!std::isfinite(td) || !std::isfinite(tdr_in) || tdr_in < 0.0) {
      return fault("a non-finite Td or Td_ref, or a negative Td_ref", td);
    }
    const double tdr = tdr_in > 0.0 ? tdr_in : p.tdr_default_us;
    error_us = tdr - td;
    vz = p.kg * error_us + p.ki * integral_us_s_;
    if (!std::isfinite(vz)) {  // finite inputs, but kg·error overflowed
      return fault("the feed command overflowed (kg times the Td error)", error_us);
    }
  }
  // max/min rather than std::clamp: no undefined behaviour for limits that bypassed validate().
  const double limited = std::min(std::max(vz, -p.v_feed_max_mm_s), p.v_retract_max_mm_s);
  const bool saturated_now = limited != vz;
  // Conditional integration: not while clamped with the error pushing the same way.
  if (law && p.ki > 0.0 && !(saturated_now && (error_us > 0.0) == (vz > 0.0))) {
    const double next = integral_us_s_ + error_us * dt_s_;
    if (std::isfinite(next)) integral_us_s_ = next;
  }
  vz_mm_s.set(limited);
  saturated.set(saturated_now);
  return saturated_now ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
