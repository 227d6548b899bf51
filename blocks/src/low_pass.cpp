#include "edm/blocks/low_pass.hpp"

#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> LowPass::configure(const rt::BlockSetup& setup) {
  period_ = setup.period;
  compute_alpha();
  return task_period_errors(setup.period);
}

void LowPass::activate() noexcept {
  y_ = params_.initial;
  out_.set(y_);
}

rt::BlockStatus LowPass::update(const rt::CycleContext& /*ctx*/) noexcept {
  const double x = in_.get();
  if (!std::isfinite(x)) {
    return fault("a non-finite input", x);
  }
  y_ += alpha_ * (x - y_);
  out_.set(y_);
  return rt::BlockStatus::kOk;
}

void LowPass::params_changed() noexcept { compute_alpha(); }

void LowPass::compute_alpha() noexcept {
  // Guards keep α in [0, 1] even for parameters that bypassed validate() (no division by zero).
  if (params_.tau.count() <= 0) {
    alpha_ = 1.0;
    return;
  }
  if (period_.count() <= 0) {
    alpha_ = 0.0;
    return;
  }
  // Ratio of two integer nanosecond counts: no rounding of either to seconds first.
  const double ratio =
      static_cast<double>(period_.count()) / static_cast<double>(params_.tau.count());
  alpha_ = -std::expm1(-ratio);
}

}  // namespace edm::blocks
