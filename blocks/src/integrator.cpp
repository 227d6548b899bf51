#include "edm/blocks/integrator.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> IntegratorParams::validate() const {
  std::vector<rt::ParamError> errs;
  require_ordered(errs, "min", min, "max", max);
  return errs;
}

std::vector<rt::ParamError> Integrator::configure(const rt::BlockSetup& setup) {
  dt_s_ = rt::to_seconds(setup.period);
  compute_gain();
  out_.set(reset_value());
  return task_period_errors(setup.period);
}

rt::BlockStatus Integrator::update(const rt::CycleContext& /*ctx*/) noexcept {
  if (reset_.get()) {
    out_.set(reset_value());
    return rt::BlockStatus::kOk;
  }
  const double x = in_.get();
  if (!std::isfinite(x)) {
    return fault("a non-finite input", x);
  }
  const double state = out_.get();
  if (!std::isfinite(state)) {
    out_.set(reset_value());
    return fault("a non-finite state: reset to its reset value", state);
  }
  const double lo = params_.min;
  const double hi = std::max(params_.max, lo);  // keeps std::clamp defined
  // An overflow to ±Inf is clamped like any other excursion; NaN (0·Inf from an absurd k·dt) is
  // not.
  const double y = state + k_dt_ * x;
  if (std::isnan(y)) {
    return fault("the integral became NaN", y);
  }
  const double clamped = std::clamp(y, lo, hi);
  out_.set(clamped);
  return clamped != y ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

void Integrator::params_changed() noexcept { compute_gain(); }

void Integrator::compute_gain() noexcept { k_dt_ = params_.k * dt_s_; }

double Integrator::reset_value() const noexcept {
  return std::clamp(params_.initial, params_.min, std::max(params_.max, params_.min));
}

}  // namespace edm::blocks
