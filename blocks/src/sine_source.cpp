#include "edm/blocks/sine_source.hpp"

#include <cmath>
#include <numbers>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

void SineSource::visit_pins(rt::PinVisitor& v) { v.output("out", out_); }

std::vector<rt::ParamError> SineSource::configure(const rt::BlockSetup& setup) {
  period_ = setup.period;
  compute_step();
  return task_period_errors(setup.period);
}

rt::BlockStatus SineSource::update(const rt::CycleContext& ctx) noexcept {
  out_.set(value_at(ctx.cycle));
  return rt::BlockStatus::kOk;
}

double SineSource::value_at(std::uint64_t cycle) const noexcept {
  // n·(hi + lo) mod 1 with n·hi split exactly into p + e (FMA), so the fraction keeps full
  // precision however large n·hi is. Exact for n < 2^53.
  const auto n = static_cast<double>(cycle);
  const double p = n * step_hi_;
  const double e = std::fma(n, step_hi_, -p) + n * step_lo_;
  double frac = (p - std::floor(p)) + e;
  frac -= std::floor(frac);
  const double angle = 2.0 * std::numbers::pi * frac + params_.phase_rad;
  return params_.offset + params_.amplitude * std::sin(angle);
}

void SineSource::params_changed() noexcept { compute_step(); }

void SineSource::compute_step() noexcept {
  // f·P/1e9 as a double-double: P (integer ns) is exact in a double below 2^53 ns (104 days);
  // the product f·P is split exactly, then divided by 1e9 with the remainder carried.
  const auto period_ns = static_cast<double>(period_.count());
  const double f = params_.frequency_hz;
  const double prod_hi = f * period_ns;
  const double prod_lo = std::fma(f, period_ns, -prod_hi);
  const double q_hi = prod_hi / 1e9;
  const double rem = std::fma(-q_hi, 1e9, prod_hi);  // exact remainder of the division
  const double q_lo = (rem + prod_lo) / 1e9;
  if (!std::isfinite(q_hi) || !std::isfinite(q_lo)) {  // parameters that bypassed validate()
    step_hi_ = 0.0;
    step_lo_ = 0.0;
    return;
  }
  step_hi_ = q_hi;
  step_lo_ = q_lo;
}

}  // namespace edm::blocks
