#include "edm/blocks/jump_cycle.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"
#include "edm/runtime/machine.hpp"

namespace edm::blocks {

namespace {

std::int64_t cycles_of(rt::Duration d, rt::Duration period) noexcept {
  if (period <= rt::Duration::zero()) {
    return 1;
  }
  return std::max<std::int64_t>(1, std::llround(rt::to_seconds(d) / rt::to_seconds(period)));
}

}  // namespace

std::vector<rt::ParamError> JumpCycleParams::validate() const {
  std::vector<rt::ParamError> errs;
  if (period <= up_time + down_time + settle_time) {
    errs.push_back({"period",
                    "must be > up_time + down_time + settle_time (the servo needs time between "
                    "jumps)"});
  }
  return errs;
}

std::vector<rt::ParamError> JumpCycle::configure(const rt::BlockSetup& setup) {
  task_period_ = setup.period;
  params_changed();
  return task_period_errors(setup.period);
}

void JumpCycle::params_changed() noexcept {
  period_n_ = cycles_of(params_.period, task_period_);
  up_n_ = cycles_of(params_.up_time, task_period_);
  down_n_ = cycles_of(params_.down_time, task_period_);
  settle_n_ =
      params_.settle_time > rt::Duration::zero() ? cycles_of(params_.settle_time, task_period_) : 0;
  // Rounding must not swallow the servo.
  period_n_ = std::max(period_n_, up_n_ + down_n_ + settle_n_ + 1);
}

void JumpCycle::reset() noexcept {
  n_ = 0;
  phase_ = -1;
  settle_left_ = 0;
  jumping_.set(false);
  settling_.set(false);
  servo_part_.set(true);
  cycle_start_.set(false);
}

void JumpCycle::activate() noexcept {
  reset();
  jumps_.set(0);
  was_enabled_ = true;
  was_safe_ = false;
  const double v = vz_in_.get();
  vz_out_.set(std::isfinite(v) ? v : 0.0);
  const double z = z_mm_.get();
  z_hold_.set(std::isfinite(z) ? z : 0.0);
}

void JumpCycle::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  reset();
  vz_out_.set(0.0);
}

rt::BlockStatus JumpCycle::update(const rt::CycleContext& ctx) noexcept {
  rt::BlockStatus status = rt::BlockStatus::kOk;
  const bool safe = rt::is_safe_state(ctx.state);
  const bool enabled = enable_.get() && !safe;
  if (enabled && (!was_enabled_ || was_safe_)) {
    n_ = 0;  // a whole period of servo before the first jump after (re-)enabling
  }
  was_enabled_ = enable_.get();
  was_safe_ = safe;

  cycle_start_.set(false);
  if (safe) {
    phase_ = -1;
  } else if (phase_ < 0 && enabled) {
    ++n_;
    if (n_ >= period_n_) {
      n_ = 0;
      phase_ = 0;
      cycle_start_.set(true);
      jumps_.set(jumps_.get() + 1);
    }
  } else if (phase_ >= 0) {
    ++n_;  // the period runs from one jump's start to the next
  }

  const bool jumping = phase_ >= 0 && phase_ < up_n_ + down_n_;
  const double z = z_mm_.get();
  if (!std::isfinite(z)) {
    status = fault("a non-finite Z position", z);
  } else if (!jumping || phase_ == 0) {
    z_hold_.set(z);  // follows z, and holds its value of the jump's first cycle
  }

  if (jumping) {
    vz_out_.set(phase_ < up_n_ ? params_.up_speed_mm_s : -params_.down_speed_mm_s);
    jumping_.set(true);
    settling_.set(true);
    servo_part_.set(false);
    ++phase_;
    return status;
  }
  if (phase_ >= 0) {
    settle_left_ = settle_n_;  // the jump ended: the approach begins
  }
  phase_ = -1;
  jumping_.set(false);
  const bool settling = settle_left_ > 0 && !safe;
  settle_left_ = settling ? settle_left_ - 1 : 0;
  settling_.set(settling);
  servo_part_.set(!settling);
  const double v = vz_in_.get();
  if (!std::isfinite(v)) {
    vz_out_.set(0.0);
    return fault("a non-finite servo feed", v);
  }
  vz_out_.set(v);
  return status;
}

}  // namespace edm::blocks
