#include "edm/programs/deep_hole_drill.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "edm/runtime/machine.hpp"

namespace edm::programs {

namespace {

// Indices of the load-time-only parameters in DeepHoleDrillParams::visit order.
constexpr std::size_t kHoleAreaIndex = 8;
constexpr std::size_t kElectrodeAreaIndex = 9;
constexpr std::size_t kTdWindowIndex = 10;

// The largest downward speed of the gap child (its default v_feed_max_mm_s): the approach speed
// is also the gap child's idle feed, which must not exceed it.
constexpr double kMaxApproachSpeed = blocks::GapControllerPParams{}.v_feed_max_mm_s;

}  // namespace

void DeepHoleDrillParams::visit(rt::ParamVisitor& v) {
  v.param("depth_default_mm", depth_default_mm, "mm",
          "target hole depth while the depth_mm input is 0 (> 0)");
  v.param("approach_speed_mm_s", approach_speed_mm_s, "mm/s",
          "feed down until the first sparks, and while the gap is open (> 0, <= 1)");
  v.param("touch_cycles", touch_cycles, "cycles",
          "consecutive cycles with sparks that count as touching the work (>= 1)");
  v.param("retract_speed_mm_s", retract_speed_mm_s, "mm/s", "upward speed of the retract (> 0)");
  v.param("clearance_mm", clearance_mm, "mm", "retract to the touch height plus this (>= 0)");
  v.param("wear_ratio_default", wear_ratio_default, "",
          "electrode/workpiece volume ratio while the wear_ratio input is <= 0 (>= 0)");
  v.param("kg", kg, "mm/s/us", "gap controller gain (> 0)");
  v.param("tdr_default_us", tdr_default_us, "us",
          "reference ignition delay while the tdr_us input is <= 0 (> 0)");
  v.param("hole_area_mm2", hole_area_mm2, "mm^2", "hole cross-section (> 0), load time only");
  v.param("electrode_area_mm2", electrode_area_mm2, "mm^2",
          "electrode material cross-section (> 0), load time only");
  v.param("td_window", td_window, "cycles", "cycles pooled for Td (1..65536), load time only");
  v.param("breakthrough_cycles", breakthrough_cycles, "cycles",
          "cycles without ignition that mean breakthrough of a through hole (>= 1)");
  v.param("breakthrough_min_mm", breakthrough_min_mm, "mm",
          "no breakthrough is detected above this depth (>= 0)");
  v.param("overtravel_mm", overtravel_mm, "mm", "feed on after breakthrough (>= 0)");
}

std::vector<rt::ParamError> DeepHoleDrillParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_positive(errs, "depth_default_mm", depth_default_mm);
  rt::require_positive(errs, "approach_speed_mm_s", approach_speed_mm_s);
  if (approach_speed_mm_s > kMaxApproachSpeed) {
    errs.push_back(
        {"approach_speed_mm_s", "approach_speed_mm_s must be <= 1 (the gap feed limit)"});
  }
  if (touch_cycles < 1) {
    errs.push_back({"touch_cycles", "touch_cycles must be >= 1"});
  }
  rt::require_positive(errs, "retract_speed_mm_s", retract_speed_mm_s);
  rt::require_finite(errs, "clearance_mm", clearance_mm);
  rt::require_non_negative(errs, "clearance_mm", clearance_mm);
  rt::require_finite(errs, "wear_ratio_default", wear_ratio_default);
  rt::require_non_negative(errs, "wear_ratio_default", wear_ratio_default);
  rt::require_positive(errs, "kg", kg);
  rt::require_positive(errs, "tdr_default_us", tdr_default_us);
  rt::require_positive(errs, "hole_area_mm2", hole_area_mm2);
  rt::require_positive(errs, "electrode_area_mm2", electrode_area_mm2);
  if (breakthrough_cycles < 1) {
    errs.push_back({"breakthrough_cycles", "breakthrough_cycles must be >= 1"});
  }
  rt::require_finite(errs, "breakthrough_min_mm", breakthrough_min_mm);
  rt::require_non_negative(errs, "breakthrough_min_mm", breakthrough_min_mm);
  rt::require_finite(errs, "overtravel_mm", overtravel_mm);
  rt::require_non_negative(errs, "overtravel_mm", overtravel_mm);
  if (td_window < 1 || td_window > blocks::TdDetectorParams::kMaxWindow) {
    errs.push_back({"td_window", "td_window must be in 1..65536"});
  }
  return errs;
}

DeepHoleDrill::DeepHoleDrill()
    : td_(add_child<blocks::TdDetector>("td")),
      gap_(add_child<blocks::GapControllerP>("gap")),
      wear_(add_child<blocks::WearCompensator>("wear")) {}

void DeepHoleDrill::visit_own_pins(rt::PinVisitor& v) {
  v.input("td_sum_ns", td_sum_ns_, "ns");
  v.input("td_count", td_count_);
  v.input("n_open", n_open_);
  v.input("n_short", n_short_);
  v.input("z_mm", z_mm_, "mm");
  v.input("start", start_);
  v.input("depth_mm", depth_mm_, "mm");
  v.input("wear_ratio", wear_ratio_);
  v.input("enable_wear_comp", enable_wear_comp_);
  v.input("tdr_us", tdr_us_, "us");
  v.input("through", through_);
  v.input("hold", hold_);
  v.input("vz_servo_mm_s", vz_servo_, "mm/s");
  v.output("vz_cmd_mm_s", vz_cmd_mm_s_, "mm/s");
  v.output("gen_on", gen_on_);
  v.output("state", state_);
  v.output("depth_reached_mm", depth_reached_mm_, "mm");
  v.output("touch_z_mm", touch_z_mm_, "mm");
  v.output("wear_mm", wear_out_mm_, "mm");
  v.output("done", done_);
  v.output("breakthrough", breakthrough_);
}

std::vector<rt::ParamError> DeepHoleDrill::configure_self(const rt::BlockSetup& setup) {
  // CompositeBlock::configure() has configured the children with their defaults; give them the
  // values derived from our parameters and configure the two that size or precompute anything
  // again (TdDetector reallocates its ring, WearCompensator recomputes A_hole/A_e and zeroes
  // wear_mm: both are load-time work, repeating it is harmless).
  std::vector<rt::ParamError> errs;
  blocks::TdDetectorParams tp = td_.params();
  tp.window = params_.td_window;
  td_.set_params(tp);
  append_child_errors(errs, "td", td_.validate());
  append_child_errors(errs, "td", td_.configure(setup));

  params_changed();  // gap: kg, tdr_default_us, idle feed
  append_child_errors(errs, "gap", gap_.validate());
  append_child_errors(errs, "gap", gap_.configure(setup));

  blocks::WearCompensatorParams wp = wear_.params();
  wp.hole_area_mm2 = params_.hole_area_mm2;
  wp.electrode_area_mm2 = params_.electrode_area_mm2;
  wear_.set_params(wp);
  append_child_errors(errs, "wear", wear_.validate());
  append_child_errors(errs, "wear", wear_.configure(setup));

  // Internal wires, resolved once.
  wire_child(errs, td_, "td", "td_sum_ns", c_td_sum_ns_);
  wire_child(errs, td_, "td", "td_count", c_td_count_);
  wire_child(errs, td_, "td", "n_open", c_n_open_);
  wire_child(errs, td_, "td", "n_short", c_n_short_);
  const rt::Output<double>* td_us = child_output<double>(errs, td_, "td", "td_us");
  const rt::Output<bool>* td_valid = child_output<bool>(errs, td_, "td", "valid");
  if (td_us != nullptr) {
    wire_child(errs, gap_, "gap", "td_us", *td_us);
  }
  if (td_valid != nullptr) {
    wire_child(errs, gap_, "gap", "valid", *td_valid);
  }
  wire_child(errs, gap_, "gap", "tdr_us", c_tdr_us_);
  gap_vz_ = child_output<double>(errs, gap_, "gap", "vz_mm_s");
  wire_child(errs, wear_, "wear", "vz_in_mm_s", c_servo_vz_);
  servo_v_min_ = -gap_.params().v_feed_max_mm_s;
  servo_v_max_ = gap_.params().v_retract_max_mm_s;
  wire_child(errs, wear_, "wear", "wear_ratio", c_wear_ratio_);
  wire_child(errs, wear_, "wear", "enable", c_wear_enable_);
  wire_child(errs, wear_, "wear", "reset_wear", c_reset_wear_);
  wear_vz_ = child_output<double>(errs, wear_, "wear", "vz_out_mm_s");
  wear_mm_ = child_output<double>(errs, wear_, "wear", "wear_mm");
  return errs;
}

void DeepHoleDrill::params_changed() noexcept {
  // Plain struct copies (no allocation): RT-safe. The gap child's parameters are not variables
  // of their own, so nothing reads its shadow copy concurrently.
  blocks::GapControllerPParams gp = gap_.params();
  gp.kg = params_.kg;
  gp.tdr_default_us = params_.tdr_default_us;
  gp.idle_feed_mm_s = -params_.approach_speed_mm_s;
  gap_.set_params(gp);
}

std::vector<rt::ParamError> DeepHoleDrill::stage_param(std::size_t index, const rt::ParamValue& v) {
  if (index == kHoleAreaIndex || index == kElectrodeAreaIndex || index == kTdWindowIndex) {
    return {{"", "load time only (set it in the config)"}};
  }
  return BlockWithParams::stage_param(index, v);
}

void DeepHoleDrill::activate_self() noexcept {
  prev_start_ = false;
  spark_cycles_ = 0;
  dark_cycles_ = 0;
  breakthrough_.set(false);
  target_depth_mm_ = params_.depth_default_mm;
  retract_to_z_mm_ = 0.0;
  safe_retract_ = false;
  c_reset_wear_.set(false);
  c_wear_enable_.set(true);
  c_servo_vz_.set(0.0);
  c_wear_ratio_.set(params_.wear_ratio_default);
  vz_cmd_mm_s_.set(0.0);
  gen_on_.set(false);
  depth_reached_mm_.set(0.0);
  touch_z_mm_.set(0.0);
  wear_out_mm_.set(0.0);
  done_.set(false);
  set_state(State::kIdle);
}

void DeepHoleDrill::set_state(State s) noexcept {
  state_value_ = s;
  state_.set(static_cast<std::int64_t>(s));
}

void DeepHoleDrill::begin_cycle() noexcept {
  const double d = depth_mm_.get();
  target_depth_mm_ = d > 0.0 ? d : params_.depth_default_mm;
  spark_cycles_ = 0;
  dark_cycles_ = 0;
  safe_retract_ = false;
  done_.set(false);
  breakthrough_.set(false);
  depth_reached_mm_.set(0.0);
  wear_out_mm_.set(0.0);
  set_state(State::kApproach);
}

void DeepHoleDrill::begin_retract(double target_z) noexcept {
  retract_to_z_mm_ = target_z;
  set_state(State::kRetract);
}

void DeepHoleDrill::safe_state_self(const rt::SafeStateRequest& /*request*/) noexcept {
  gen_on_.set(false);
  if (state_value_ == State::kDrill || state_value_ == State::kBreakthrough) {
    begin_retract(touch_z_mm_.get() + params_.clearance_mm);
    safe_retract_ = true;
  } else if (state_value_ == State::kApproach) {
    begin_retract(z_mm_.get() + params_.clearance_mm);
    safe_retract_ = true;
  }
  if (state_value_ == State::kRetract) {
    vz_cmd_mm_s_.set(params_.retract_speed_mm_s);
  } else {
    vz_cmd_mm_s_.set(0.0);
  }
}

rt::BlockStatus DeepHoleDrill::update(const rt::CycleContext& ctx) noexcept {
  const bool safe = rt::is_safe_state(ctx.state);
  const bool start = start_.get();
  const bool rising = start && !prev_start_;
  prev_start_ = start;
  const double z = z_mm_.get();
  const bool comp = enable_wear_comp_.get();

  c_td_sum_ns_.set(td_sum_ns_.get());
  c_td_count_.set(td_count_.get());
  c_n_open_.set(n_open_.get());
  c_n_short_.set(n_short_.get());
  const double w = wear_ratio_.get();
  c_wear_ratio_.set(w > 0.0 ? w : params_.wear_ratio_default);
  c_wear_enable_.set(comp);
  const double tdr = tdr_us_.get();
  c_tdr_us_.set(tdr > 0.0 && std::isfinite(tdr) ? tdr : 0.0);  // 0: the gap child's parameter

  if (safe && (state_value_ == State::kApproach || state_value_ == State::kDrill ||
               state_value_ == State::kBreakthrough)) {
    // Normally done by safe_state_self(); kept here so no path can drill in a safe state.
    safe_state_self(rt::SafeStateRequest{});
  }

  rt::BlockStatus status = rt::BlockStatus::kOk;
  if ((state_value_ == State::kIdle || state_value_ == State::kDone) && rising && !safe) {
    begin_cycle();
  }

  // HOLD (operator feed hold) while approaching or drilling: generator off, Z still; the gap,
  // Td and wear children are not stepped, so nothing is learnt or integrated meanwhile and the
  // cycle continues where it was on release.
  if (hold_.get() && !safe && (state_value_ == State::kApproach || state_value_ == State::kDrill)) {
    gen_on_.set(false);
    vz_cmd_mm_s_.set(0.0);
    spark_cycles_ = 0;
    return status;
  }

  bool td_stepped = false;
  if (state_value_ == State::kApproach) {
    status = rt::worst(status, td_.update(ctx));  // fills the Td window before the gap loop starts
    td_stepped = true;
    spark_cycles_ = td_count_.get() > 0 ? spark_cycles_ + 1 : 0;
    if (spark_cycles_ >= params_.touch_cycles) {
      touch_z_mm_.set(z);
      c_reset_wear_.set(true);  // the wear estimate starts at the touch
      set_state(State::kDrill);
    } else {
      gen_on_.set(true);
      vz_cmd_mm_s_.set(-params_.approach_speed_mm_s);
    }
  }

  if (state_value_ == State::kDrill) {
    if (!td_stepped) {
      status = rt::worst(status, td_.update(ctx));
    }
    status = rt::worst(status, gap_.update(ctx));
    if (vz_servo_.connected()) {
      const double v = vz_servo_.get();
      if (std::isfinite(v)) {
        c_servo_vz_.set(std::clamp(v, servo_v_min_, servo_v_max_));
      } else {
        c_servo_vz_.set(0.0);
        status = rt::worst(status, rt::BlockStatus::kFault);
      }
    } else {
      c_servo_vz_.set(gap_vz_ != nullptr ? gap_vz_->get() : 0.0);
    }
    status = rt::worst(status, wear_.update(ctx));
    c_reset_wear_.set(false);
    // The electrode front is z − accumulated wear: the compensated axis travels further than the
    // front by the length the compensator has added for the wear, so the front (≈ the hole
    // bottom, one working gap away) has gone (touch_z − z) − wear_mm below the touch point.
    const double wear_mm = comp && wear_mm_ != nullptr ? wear_mm_->get() : 0.0;
    const double depth = (touch_z_mm_.get() - z) - wear_mm;
    depth_reached_mm_.set(depth);
    wear_out_mm_.set(wear_mm);
    dark_cycles_ = td_count_.get() > 0 ? 0 : dark_cycles_ + 1;
    if (depth >= target_depth_mm_) {
      begin_retract(touch_z_mm_.get() + params_.clearance_mm);
    } else if (through_.get() && depth >= params_.breakthrough_min_mm &&
               dark_cycles_ >= params_.breakthrough_cycles) {
      breakthrough_.set(true);
      breakthrough_z_mm_ = z;
      set_state(State::kBreakthrough);
    } else {
      gen_on_.set(true);
      vz_cmd_mm_s_.set(wear_vz_ != nullptr ? wear_vz_->get() : 0.0);
    }
  }

  if (state_value_ == State::kBreakthrough) {
    gen_on_.set(false);
    if (z <= breakthrough_z_mm_ - params_.overtravel_mm) {
      begin_retract(touch_z_mm_.get() + params_.clearance_mm);
    } else {
      vz_cmd_mm_s_.set(-params_.approach_speed_mm_s);
    }
  }

  if (state_value_ == State::kRetract) {
    gen_on_.set(false);
    if (z >= retract_to_z_mm_) {
      vz_cmd_mm_s_.set(0.0);
      done_.set(!safe_retract_);
      set_state(safe_retract_ ? State::kIdle : State::kDone);
      safe_retract_ = false;
    } else {
      vz_cmd_mm_s_.set(params_.retract_speed_mm_s);
    }
  } else if (state_value_ == State::kIdle || state_value_ == State::kDone) {
    gen_on_.set(false);
    vz_cmd_mm_s_.set(0.0);
  }
  return status;
}

}  // namespace edm::programs
