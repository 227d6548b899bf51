#include "edm/blocks/wear_compensator.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> WearCompensatorParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_positive(errs, "hole_area_mm2", hole_area_mm2);
  rt::require_finite(errs, "hole_area_mm2", hole_area_mm2);
  rt::require_positive(errs, "electrode_area_mm2", electrode_area_mm2);
  rt::require_finite(errs, "electrode_area_mm2", electrode_area_mm2);
  rt::require_positive(errs, "wear_ratio_max", wear_ratio_max);
  rt::require_finite(errs, "wear_ratio_max", wear_ratio_max);
  return errs;
}

void WearCompensator::visit_pins(rt::PinVisitor& v) {
  v.input("vz_in_mm_s", vz_in_mm_s_, "mm/s");
  v.input("wear_ratio", wear_ratio_);
  v.input("enable", enable_);
  v.input("reset_wear", reset_wear_);
  v.output("vz_out_mm_s", vz_out_mm_s_, "mm/s");
  v.output("vd_mm_s", vd_mm_s_, "mm/s");
  v.output("wear_mm", wear_mm_, "mm");
}

std::vector<rt::ParamError> WearCompensator::configure(const rt::BlockSetup& setup) {
  std::vector<rt::ParamError> errs;
  require_task_period(errs, setup.period);
  dt_s_ = rt::to_seconds(setup.period);
  compute_ratio();
  wear_mm_.set(0.0);
  front_mm_ = 0.0;
  deepest_mm_ = 0.0;
  vd_mm_s_.set(0.0);
  vz_out_mm_s_.set(0.0);
  return errs;
}

void WearCompensator::params_changed() noexcept { compute_ratio(); }

void WearCompensator::compute_ratio() noexcept {
  area_ratio_ = params_.hole_area_mm2 / params_.electrode_area_mm2;
}

rt::BlockStatus WearCompensator::update(const rt::CycleContext& ctx) noexcept {
  rt::BlockStatus status = rt::BlockStatus::kOk;
  double wear = wear_mm_.get();
  if (reset_wear_.get()) {
    wear = 0.0;
    front_mm_ = 0.0;
    deepest_mm_ = 0.0;
    have_release_ = false;
  } else if (!std::isfinite(wear)) {  // a corrupt restored value
    wear = 0.0;
    status = rt::BlockStatus::kFault;
  }
  // The time since the last cycle, not the period: omitted cycles (the axis kept its last
  // command) count too.
  // A gap of more than 10 periods is a pause of the block (e.g. a feed hold in which it is not
  // stepped), not omitted cycles: it counts as one period.
  double elapsed_s = dt_s_;
  if (have_release_ && ctx.release > last_release_) {
    const double gap_s = rt::to_seconds(ctx.release - last_release_);
    elapsed_s = gap_s <= 10.0 * dt_s_ ? std::max(gap_s, dt_s_) : dt_s_;
  }
  have_release_ = true;
  last_release_ = ctx.release;
  const double vz_in = vz_in_mm_s_.get();
  if (!std::isfinite(vz_in)) {
    vz_out_mm_s_.set(0.0);
    vd_mm_s_.set(0.0);
    wear_mm_.set(wear);
    return rt::BlockStatus::kFault;
  }
  // High-water mark of the front: only depth never reached before is erosion progress.
  front_mm_ += vz_in * elapsed_s;
  if (!std::isfinite(front_mm_)) {  // absurd feeds: restart the tracking, compensate nothing
    front_mm_ = 0.0;
    deepest_mm_ = 0.0;
    status = rt::BlockStatus::kFault;
  }
  double new_depth_mm = 0.0;
  if (-front_mm_ > deepest_mm_) {
    new_depth_mm = -front_mm_ - deepest_mm_;
    deepest_mm_ = -front_mm_;
  }
  double vd = 0.0;
  if (enable_.get() && new_depth_mm > 0.0) {
    const double ratio_in = wear_ratio_.get();
    if (!std::isfinite(ratio_in)) {
      status = rt::BlockStatus::kFault;
    } else {
      const double ratio = std::clamp(ratio_in, 0.0, params_.wear_ratio_max);
      if (ratio != ratio_in && status == rt::BlockStatus::kOk) {
        status = rt::BlockStatus::kSaturated;
      }
      vd = ratio * area_ratio_ * new_depth_mm / dt_s_;  // v_bottom = new depth per cycle
    }
  }
  const double vz_out = vz_in - vd;
  const double wear_next = wear + vd * dt_s_;
  if (!std::isfinite(vz_out) || !std::isfinite(wear_next)) {  // overflow from absurd inputs
    vz_out_mm_s_.set(vz_in);
    vd_mm_s_.set(0.0);
    wear_mm_.set(wear);
    return rt::BlockStatus::kFault;
  }
  vz_out_mm_s_.set(vz_out);
  vd_mm_s_.set(vd);
  wear_mm_.set(wear_next);
  return status;
}

}  // namespace edm::blocks
