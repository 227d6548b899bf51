#include "edm/blocks/moving_average.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {
void MovingAverage::CompensatedSum::add(double x) noexcept {
  // Knuth's TwoSum: s + e == hi + x exactly (needs strict IEEE evaluation: no -ffast-math).
  const double s = hi + x;
  const double b = s - hi;
  const double e = (hi - (s - b)) + (x - b);
  hi = s;
  lo += e;
}

std::vector<rt::ParamError> MovingAverage::configure(const rt::BlockSetup& /*setup*/) {
  return configure_checked(params_, [this] {
    window_.allocate(static_cast<std::size_t>(params_.window));
    activate();
  });
}

void MovingAverage::activate() noexcept {
  window_.clear();
  sum_ = {};
  pass_sum_ = {};
  out_.set(0.0);
  full_.set(false);
}

rt::BlockStatus MovingAverage::update(const rt::CycleContext& /*ctx*/) noexcept {
  const double x = in_.get();
  if (!std::isfinite(x) || window_.capacity() == 0) {  // capacity 0: not configured
    return fault("a non-finite input, or not configured", x);
  }
  const double old = window_.push(x);  // 0 until the window is full
  sum_.add(x);
  sum_.add(-old);
  pass_sum_.add(x);
  if (window_.at_first_slot()) {
    // The buffer now holds exactly the samples of this pass: restart from their sum.
    sum_ = pass_sum_;
    pass_sum_ = {};
  }
  const double mean = sum_.value() / static_cast<double>(window_.size());
  full_.set(window_.full());
  if (!std::isfinite(mean)) {
    return fault("a non-finite mean", mean);
  }
  out_.set(mean);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
