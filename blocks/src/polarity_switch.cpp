#include "edm/blocks/polarity_switch.hpp"

#include <algorithm>

namespace edm::blocks {

void PolaritySwitch::activate() noexcept {
  polarity_ = params_.initial_positive;
  gen_on_ = false;
  started_ = false;
  polarity_positive.set(polarity_);
  generator_on.set(false);
  switching.set(true);
}

rt::BlockStatus PolaritySwitch::update(const rt::CycleContext& ctx) noexcept {
  const rt::TimePoint now = ctx.release;
  if (!started_) {
    // The relay state before activation is unknown: count activation as a switch.
    started_ = true;
    off_since_ = now;
    last_switch_ = now;
  }
  // At least 1 ns, so that the generator is off for at least one cycle on each side of a switch
  // even with a settle that bypassed validate().
  const rt::Duration settle = std::max(params_.settle, rt::Duration{1});
  const bool request = request_positive.get();

  if (request != polarity_) {
    if (gen_on_) {
      gen_on_ = false;
      off_since_ = now;
    }
    if (now - off_since_ >= settle && now - last_switch_ >= settle) {
      polarity_ = request;
      last_switch_ = now;
    }
  }
  const bool allowed = request == polarity_ && now - last_switch_ >= settle;
  const bool gen_on = allowed && generator_on_request.get();
  if (gen_on_ && !gen_on) {
    off_since_ = now;
  }
  gen_on_ = gen_on;

  polarity_positive.set(polarity_);
  generator_on.set(gen_on_);
  switching.set(!allowed);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
