#include "edm/blocks/position_loop.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

std::vector<rt::ParamError> PositionLoopParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_non_negative(errs, "kv", kv);
  rt::require_finite(errs, "kv", kv);
  rt::require_non_negative(errs, "ki", ki);
  rt::require_finite(errs, "ki", ki);
  rt::require_range(errs, "kff", kff, 0.0, 1.5);
  rt::require_positive(errs, "v_max_mm_s", v_max_mm_s);
  rt::require_finite(errs, "v_max_mm_s", v_max_mm_s);
  rt::require_positive(errs, "f_err_max_mm", f_err_max_mm);
  rt::require_finite(errs, "f_err_max_mm", f_err_max_mm);
  rt::require_non_negative(errs, "in_pos_tol_mm", in_pos_tol_mm);
  rt::require_finite(errs, "in_pos_tol_mm", in_pos_tol_mm);
  rt::require_range(errs, "in_pos_cycles", static_cast<double>(in_pos_cycles), 1.0, 1.0e9);
  return errs;
}

void PositionLoop::visit_pins(rt::PinVisitor& v) {
  v.input("x_ref_mm", x_ref_mm_, "mm");
  v.input("v_ff_mm_s", v_ff_mm_s_, "mm/s");
  v.input("x_mm", x_mm_, "mm");
  v.input("enable", enable_);
  v.input("reset", reset_);
  v.output("v_cmd_mm_s", v_cmd_mm_s_, "mm/s");
  v.output("error_mm", error_mm_, "mm");
  v.output("in_position", in_position_);
  v.output("following_error_fault", following_error_fault_);
  v.output("saturated", saturated_);
}

std::vector<rt::ParamError> PositionLoop::configure(const rt::BlockSetup& setup) {
  std::vector<rt::ParamError> errs;
  require_task_period(errs, setup.period);
  dt_s_ = rt::to_seconds(setup.period);
  activate();
  return errs;
}

void PositionLoop::activate() noexcept {
  integral_mm_s_ = 0.0;
  in_pos_count_ = 0;
  fault_latched_ = false;
  v_cmd_mm_s_.set(0.0);
  error_mm_.set(0.0);
  in_position_.set(false);
  following_error_fault_.set(false);
  saturated_.set(false);
}

void PositionLoop::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  integral_mm_s_ = 0.0;
  v_cmd_mm_s_.set(0.0);
  saturated_.set(false);
}

rt::BlockStatus PositionLoop::update(const rt::CycleContext& /*ctx*/) noexcept {
  const PositionLoopParams& p = params_;
  if (reset_.get()) {
    fault_latched_ = false;
  }
  const double x_ref = x_ref_mm_.get();
  const double v_ff = v_ff_mm_s_.get();
  const double x = x_mm_.get();
  const double e = x_ref - x;
  if (!std::isfinite(x_ref) || !std::isfinite(v_ff) || !std::isfinite(x) || !std::isfinite(e)) {
    v_cmd_mm_s_.set(0.0);
    saturated_.set(false);
    in_pos_count_ = 0;
    in_position_.set(false);
    following_error_fault_.set(fault_latched_);
    return rt::BlockStatus::kFault;
  }
  error_mm_.set(e);
  in_pos_count_ = std::abs(e) <= p.in_pos_tol_mm ? std::min(in_pos_count_ + 1, p.in_pos_cycles)
                                                 : std::int64_t{0};
  in_position_.set(in_pos_count_ >= p.in_pos_cycles);

  const bool enabled = enable_.get();
  if (enabled && std::abs(e) > p.f_err_max_mm) {
    fault_latched_ = true;
  }
  following_error_fault_.set(fault_latched_);
  if (!enabled || fault_latched_) {
    integral_mm_s_ = 0.0;
    v_cmd_mm_s_.set(0.0);
    saturated_.set(false);
    return fault_latched_ ? rt::BlockStatus::kFault : rt::BlockStatus::kOk;
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
    v_cmd_mm_s_.set(0.0);
    saturated_.set(false);
    return rt::BlockStatus::kFault;
  }
  integral_mm_s_ = integral;
  const double v_cmd = std::clamp(v, -v_lim, v_lim);
  const bool sat = v_cmd != v;
  v_cmd_mm_s_.set(v_cmd);
  saturated_.set(sat);
  return sat ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
