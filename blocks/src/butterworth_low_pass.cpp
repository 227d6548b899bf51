#include "edm/blocks/butterworth_low_pass.hpp"

#include <cmath>
#include <numbers>

namespace edm::blocks {

ButterworthLowPass::Coefficients ButterworthLowPass::design(double wn) noexcept {
  if (!(wn > 0.0 && wn < 1.0)) {
    return {};
  }
  const double k = std::tan(std::numbers::pi * wn / 2.0);
  const double k2 = k * k;
  const double r2k = std::numbers::sqrt2 * k;
  const double d = 1.0 + r2k + k2;
  Coefficients c;
  c.b0 = k2 / d;
  c.b1 = 2.0 * c.b0;
  c.b2 = c.b0;
  c.a1 = 2.0 * (k2 - 1.0) / d;
  c.a2 = (1.0 - r2k + k2) / d;
  return c;
}

std::vector<rt::ParamError> ButterworthLowPass::configure(const rt::BlockSetup& /*setup*/) {
  c_ = design(params_.cutoff);
  return {};
}

void ButterworthLowPass::activate() noexcept {
  set_state(params_.initial);
  primed_ = !params_.prime;
  out_.set(params_.initial);
}

void ButterworthLowPass::set_state(double v) noexcept { x1_ = x2_ = y1_ = y2_ = v; }

rt::BlockStatus ButterworthLowPass::update(const rt::CycleContext& /*ctx*/) noexcept {
  const double x = in_.get();
  if (!std::isfinite(x)) {
    return fault("a non-finite input", x);
  }
  if (!primed_) {
    set_state(x);
    primed_ = true;
  }
  const double y = c_.b0 * x + c_.b1 * x1_ + c_.b2 * x2_ - c_.a1 * y1_ - c_.a2 * y2_;
  x2_ = x1_;
  x1_ = x;
  y2_ = y1_;
  y1_ = y;
  out_.set(y);
  return rt::BlockStatus::kOk;
}

void ButterworthLowPass::params_changed() noexcept { c_ = design(params_.cutoff); }

}  // namespace edm::blocks
