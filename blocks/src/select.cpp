#include "edm/blocks/select.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> Select::configure(const rt::BlockSetup& setup) {
  dt_s_ = rt::to_seconds(setup.period);
  return task_period_errors(setup.period);
}

void Select::activate() noexcept {
  has_prev_ = false;
  bump_ = ramp_left_s_ = ramp_total_s_ = 0.0;
  // Blocks ahead of this one in the program, and readers in other tasks, may read the outputs
  // before the first update: give them the selection and the selected input's value now. The
  // blocks ahead are activated first, so a g wired to another Select's active1 is already set.
  const bool sel = g_.get() || params_.select;
  active0_.set(!sel);
  active1_.set(sel);
  transferring_.set(false);
  const double src = sel ? in1_.get() : in0_.get();
  out_.set(std::isfinite(src) ? src : 0.0);
}

rt::BlockStatus Select::update(const rt::CycleContext& /*ctx*/) noexcept {
  const bool sel = g_.get() || params_.select;
  const double src = sel ? in1_.get() : in0_.get();
  if (!std::isfinite(src)) {
    return fault("the selected input is not finite", src);
  }
  if (has_prev_ && sel != sel_) {
    ramp_total_s_ = rt::to_seconds(params_.ramp_time);
    ramp_left_s_ = ramp_total_s_;
    bump_ = ramp_total_s_ > 0.0 ? out_.get() - src : 0.0;
  } else if (ramp_left_s_ > 0.0) {
    ramp_left_s_ = std::max(0.0, ramp_left_s_ - dt_s_);
  }
  const double weight = ramp_total_s_ > 0.0 ? ramp_left_s_ / ramp_total_s_ : 0.0;
  out_.set(src + bump_ * weight);
  sel_ = sel;
  has_prev_ = true;
  active0_.set(!sel);
  active1_.set(sel);
  transferring_.set(weight > 0.0);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
