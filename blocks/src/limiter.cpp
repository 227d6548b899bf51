#include "edm/blocks/limiter.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> LimiterParams::validate() const {
  std::vector<rt::ParamError> errs;
  require_ordered(errs, "min", min, "max", max);
  return errs;
}

std::vector<rt::ParamError> Limiter::configure(const rt::BlockSetup& setup) {
  dt_s_ = rt::to_seconds(setup.period);
  compute_step();
  return task_period_errors(setup.period);
}

void Limiter::activate() noexcept { has_prev_ = false; }

rt::BlockStatus Limiter::update(const rt::CycleContext& /*ctx*/) noexcept {
  const double x = in_.get();
  if (!std::isfinite(x)) {
    return fault("a non-finite input", x);
  }
  const double lo = params_.min;
  // std::clamp is undefined for hi < lo; a bad runtime write cannot get here (validate), but stay
  // defined anyway.
  const double hi = std::max(params_.max, lo);
  const double target = std::clamp(x, lo, hi);
  double y = target;
  if (has_prev_ && max_step_ > 0.0) {
    const double delta = target - y_;
    if (delta > max_step_) {
      y = y_ + max_step_;
    } else if (delta < -max_step_) {
      y = y_ - max_step_;
    }
    y = std::clamp(y, lo, hi);
  }
  const bool limited = target != x || y != target;
  y_ = y;
  has_prev_ = true;
  out_.set(y);
  limited_.set(limited);
  return limited ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

void Limiter::params_changed() noexcept { compute_step(); }

void Limiter::compute_step() noexcept {
  // A non-finite or negative step (parameters that bypassed validate()) means "unlimited".
  const double step = params_.rate * dt_s_;
  max_step_ = std::isfinite(step) && step > 0.0 ? step : 0.0;
}

}  // namespace edm::blocks
