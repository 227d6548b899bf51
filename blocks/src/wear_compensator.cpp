#include "edm/blocks/wear_compensator.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> WearCompensatorParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_ordered(errs, "wear_ratio_default", wear_ratio_default, "wear_ratio_max",
                      wear_ratio_max);
  return errs;
}

std::vector<rt::ParamError> WearCompensator::configure(const rt::BlockSetup& setup) {
  std::vector<rt::ParamError> errs;
  require_task_period(errs, setup.period);
  dt_s_ = rt::to_seconds(setup.period);
  compute_ratio();
  wear_mm.set(0.0);
  front_mm_ = 0.0;
  deepest_mm_ = 0.0;
  vd_mm_s.set(0.0);
  vz_out_mm_s.set(0.0);
  return errs;
}

void WearCompensator::params_changed() noexcept { compute_ratio(); }

void WearCompensator::compute_ratio() noexcept {
  area_ratio_ = params_.hole_area_mm2 / params_.electrode_area_mm2;
}

rt::BlockStatus WearCompensator::update(const rt::CycleContext& ctx) noexcept {
  rt::BlockStatus status = rt::BlockStatus::kOk;
  double wear = wear_mm.get();
  if (reset_wear.get()) {
    wear = 0.0;
    front_mm_ = 0.0;
    deepest_mm_ = 0.0;
    have_release_ = false;
  } else if (!std::isfinite(wear)) {  // a corrupt restored value
    wear = 0.0;
    status = fault("a non-finite restored wear: reset to 0", wear);
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
  const double vz_in = vz_in_mm_s.get();
  if (!std::isfinite(vz_in)) {
    vz_out_mm_s.set(0.0);
    vd_mm_s.set(0.0);
    wear_mm.set(wear);
    return fault("a non-finite feed", vz_in);
  }
  // High-water mark of the front: only depth never reached before is erosion progress.
  front_mm_ += vz_in * elapsed_s;
  if (!std::isfinite(front_mm_)) {  // absurd feeds: restart the tracking, compensate nothing
    front_mm_ = 0.0;
    deepest_mm_ = 0.0;
    status = fault("the front tracking overflowed (absurd feeds): restarted", front_mm_);
  }
  double new_depth_mm = 0.0;
  if (-front_mm_ > deepest_mm_) {
    new_depth_mm = -front_mm_ - deepest_mm_;
    deepest_mm_ = -front_mm_;
  }
  double vd = 0.0;
  if (enable.get() && new_depth_mm > 0.0) {
    const double ratio_in = wear_ratio.get();
    if (!std::isfinite(ratio_in)) {
      status = fault("a non-finite wear ratio", ratio_in);
    } else {
      // No estimate (<= 0; an unwired input reads 0): the parameter's θ. With the default 0 this
      // is the input itself, sign of zero included.
      const double default_ratio = params_.wear_ratio_default;
      const double wanted = ratio_in <= 0.0 && default_ratio > 0.0 ? default_ratio : ratio_in;
      const double ratio = std::clamp(wanted, 0.0, params_.wear_ratio_max);
      if ((ratio != wanted || ratio_in < 0.0) && status == rt::BlockStatus::kOk) {
        status = rt::BlockStatus::kSaturated;
      }
      const double area_in = area_ratio.get();
      if (!std::isfinite(area_in)) status = fault("a non-finite area ratio", area_in);
      const double areas = area_in > 0.0 && std::isfinite(area_in) ? area_in : area_ratio_;
      vd = ratio * areas * new_depth_mm / dt_s_;  // v_bottom = new depth per cycle
    }
  }
  const double vz_out = vz_in - vd;
  const double wear_next = wear + vd * dt_s_;
  if (!std::isfinite(vz_out) || !std::isfinite(wear_next)) {  // overflow from absurd inputs
    vz_out_mm_s.set(vz_in);
    vd_mm_s.set(0.0);
    wear_mm.set(wear);
    return fault("the compensated feed or the wear overflowed", vz_in);
  }
  vz_out_mm_s.set(vz_out);
  vd_mm_s.set(vd);
  wear_mm.set(wear_next);
  return status;
}

}  // namespace edm::blocks
