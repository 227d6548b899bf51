#include "edm/blocks/gap_controller_p.hpp"

#include <algorithm>
#include <cmath>

namespace edm::blocks {

std::vector<rt::ParamError> GapControllerPParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_finite(errs, "kg", kg);
  rt::require_finite(errs, "tdr_default_us", tdr_default_us);
  rt::require_finite(errs, "v_feed_max_mm_s", v_feed_max_mm_s);
  rt::require_finite(errs, "v_retract_max_mm_s", v_retract_max_mm_s);
  rt::require_finite(errs, "retract_speed_mm_s", retract_speed_mm_s);
  rt::require_finite(errs, "idle_feed_mm_s", idle_feed_mm_s);
  if (!errs.empty()) {
    return errs;
  }
  rt::require_positive(errs, "kg", kg);
  rt::require_positive(errs, "tdr_default_us", tdr_default_us);
  rt::require_positive(errs, "v_feed_max_mm_s", v_feed_max_mm_s);
  rt::require_positive(errs, "v_retract_max_mm_s", v_retract_max_mm_s);
  rt::require_positive(errs, "retract_speed_mm_s", retract_speed_mm_s);
  rt::require_range(errs, "idle_feed_mm_s", idle_feed_mm_s, -v_feed_max_mm_s, 0.0);
  if (errs.empty()) {
    rt::require_ordered(errs, "retract_speed_mm_s", retract_speed_mm_s, "v_retract_max_mm_s",
                        v_retract_max_mm_s);
  }
  return errs;
}

void GapControllerP::visit_pins(rt::PinVisitor& v) {
  v.input("td_us", td_us_, "us");
  v.input("valid", valid_);
  v.input("enable", enable_);
  v.input("hold", hold_);
  v.input("retract", retract_);
  v.input("tdr_us", tdr_us_, "us");
  v.output("vz_mm_s", vz_mm_s_, "mm/s");
  v.output("saturated", saturated_);
}

void GapControllerP::activate() noexcept {
  vz_mm_s_.set(0.0);
  saturated_.set(false);
}

rt::BlockStatus GapControllerP::update(const rt::CycleContext& /*ctx*/) noexcept {
  const auto& p = params_;
  if (retract_.get()) {
    // Validated retract_speed ≤ v_retract_max; the limit guards a direct set_params().
    vz_mm_s_.set(std::min(p.retract_speed_mm_s, p.v_retract_max_mm_s));
    saturated_.set(false);
    return rt::BlockStatus::kOk;
  }
  if (!enable_.get() || hold_.get()) {
    vz_mm_s_.set(0.0);
    saturated_.set(false);
    return rt::BlockStatus::kOk;
  }
  double vz = p.idle_feed_mm_s;
  if (valid_.get()) {
    const double td = td_us_.get();
    const double tdr_in = tdr_us_.get();
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
  const bool saturated = limited != vz;
  vz_mm_s_.set(limited);
  saturated_.set(saturated);
  return saturated ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
