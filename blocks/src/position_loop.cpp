#include "edm/blocks/position_loop.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> PositionLoop::configure(const rt::BlockSetup& setup) {
  dt_s_ = rt::to_seconds(setup.period);
  activate();
  return task_period_errors(setup.period);
}

void PositionLoop::activate() noexcept {
  integral_mm_s_ = 0.0;
  in_pos_count_ = 0;
  fault_latched_ = false;
  v_cmd_mm_s.set(0.0);
  error_mm.set(0.0);
  in_position.set(false);
  following_error_fault.set(false);
  saturated.set(false);
}

void PositionLoop::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  integral_mm_s_ = 0.0;
  v_cmd_mm_s.set(0.0);
  saturated.set(false);
}

rt::BlockStatus PositionLoop::update(const rt::CycleContext& /*ctx*/) noexcept {
  const PositionLoopParams& p = params_;
  if (reset.get()) {
    fault_latched_ = false;
  }
  const double x_ref = x_ref_mm.get();
  const double v_ff = v_ff_mm_s.get();
  const double x = x_mm.get();
  const double e = x_ref - x;
  if (!std::isfinite(x_ref) || !std::isfinite(v_ff) || !std::isfinite(x) || !std::isfinite(e)) {
    v_cmd_mm_s.set(0.0);
    saturated.set(false);
    in_pos_count_ = 0;
    in_position.set(false);
    following_error_fault.set(fault_latched_);
    return fault("a non-finite reference, feed-forward or position", x);
  }
  error_mm.set(e);
  in_pos_count_ = std::abs(e) <= p.in_pos_tol_mm ? std::min(in_pos_count_ + 1, p.in_pos_cycles)
                                                 : std::int64_t{0};
  in_position.set(in_pos_count_ >= p.in_pos_cycles);

  const bool enabled = enable.get();
  if (enabled && std::abs(e) > p.f_err_max_mm) {
    fault_latched_ = true;
  }
  following_error_fault.set(fault_latched_);
  if (!enabled || fault_latched_) {
    integral_mm_s_ = 0.0;
    v_cmd_mm_s.set(0.0);
    saturated.set(false);
    return fault_latched_ ? fault("following error beyond f_err_max_mm (latched until reset)", e)
                          : rt::BlockStatus::kOk;
  }

  const double v_lim = p.v_max_mm_s;
  const double v_open = p.kv * e + p.kff * v_ff;
  double integral = integral_mm_s_ + e * dt_s_;
  double v = v_open + p.ki * integral;
  if (std::abs(v) > v_lim && e * v > 0.0) {
    integral = integral_mm_s_;  // conditional integration: no windup into the limit
    v = v_open + p.ki * integral;
  }
  if (std::isnan(v)) {  // only from absurd gains (0·Inf); keep the state clean
    v_cmd_mm_s.set(0.0);
    saturated.set(false);
    return fault("the velocity command is NaN (absurd gains)");
  }
  integral_mm_s_ = integral;
  const double v_cmd = std::clamp(v, -v_lim, v_lim);
  const bool sat = v_cmd != v;
  v_cmd_mm_s.set(v_cmd);
  saturated.set(sat);
  return sat ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
