#include "edm/programs/deep_hole_drill.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/machine.hpp"

namespace edm::programs {

namespace {

// The largest downward speed of the gap child (its default v_feed_max_mm_s): the approach must
// not be faster than the servo may feed.
constexpr double kMaxApproachSpeed = blocks::GapControllerPParams{}.v_feed_max_mm_s;

}  // namespace

void DeepHoleDrillParams::visit(rt::ParamVisitor& v) {
  namespace r = blocks::ranges;  // the shared physical ranges (param_ranges.hpp)
  v.param("depth_default_mm", depth_default_mm,
          {"mm", "target hole depth while the depth_mm input is 0", r::kPositiveLengthMm});
  v.param("approach_speed_mm_s", approach_speed_mm_s,
          {"mm/s", "feed down until the first sparks (at most the gap feed limit)",
           rt::open_closed(0.0, kMaxApproachSpeed)});
  v.param("spark_gap_offset_um", spark_gap_offset_um,
          {"um",
           "frontal gap at the first sparks less the working gap: the hole is this much shallower "
           "than the front's travel from the touch",
           rt::closed(-1000.0, 1000.0)});
  v.param("contact_offset_um", contact_offset_um,
          {"um",
           "working gap less the touch-sensing distance: a hole measured by touch "
           "(contact_depth_mm) is this much deeper than the front's travel from the contact",
           rt::closed(-1000.0, 1000.0)});
  v.param("touch_cycles", touch_cycles,
          {"cycles", "consecutive cycles with sparks that count as touching the work", r::kCycles});
  v.param("retract_speed_mm_s", retract_speed_mm_s,
          {"mm/s", "upward speed of the retract", r::kSpeedMmS});
  v.param("clearance_mm", clearance_mm,
          {"mm", "retract to the touch height plus this", r::kLengthMm});
  // Up to 1e7 cycles: 1000 s at the 10 kHz task, 10^4 s at 1 kHz.
  v.param("breakthrough_cycles", breakthrough_cycles,
          {"cycles", "cycles without ignition that mean breakthrough of a through hole",
           rt::closed(1.0, 1.0e7)});
  v.param("breakthrough_min_mm", breakthrough_min_mm,
          {"mm", "no breakthrough is detected above this depth", r::kLengthMm});
  v.param("overtravel_mm", overtravel_mm, {"mm", "feed on after breakthrough", r::kLengthMm});
  shorts.visit(v);
  v.param("short_backoff_mm", short_backoff_mm,
          {"mm", "Z backs off this far on alarm 150, generator off, then holds", r::kLengthMm});
}

DeepHoleDrill::DeepHoleDrill()
    : td_(add_child<blocks::TdDetector>("td")),
      gap_(add_child<blocks::GapControllerP>("gap")),
      wear_(add_child<blocks::WearCompensator>("wear")),
      retract_(add_child<blocks::ShortRetract>("retract")),
      zloop_(add_child<blocks::PositionLoop>("zloop")) {
  // This program's defaults for its children (variables of their own, set in YAML).
  blocks::GapControllerPParams gp;
  gp.idle_feed_mm_s = -DeepHoleDrillParams{}.approach_speed_mm_s;
  gap_.set_params(gp);
  blocks::WearCompensatorParams wp;
  wp.wear_ratio_default = 0.6;
  wear_.set_params(wp);
  blocks::ShortRetractParams rp;
  rp.short_cycles = 5;  // with td.window: the detection window
  rp.max_tries = 1000;  // the retract budget is this program's (short_retracts_max in a window)
  retract_.set_params(rp);
  blocks::PositionLoopParams zp;
  zp.kv = 50.0;
  zp.v_max_mm_s = 10.0;
  zloop_.set_params(zp);
}

std::vector<rt::ParamError> DeepHoleDrill::configure_self(const rt::BlockSetup& setup) {
  machine_ = setup.machine;
  source_name_ = std::string(setup.instance);
  source_ = source_name_.c_str();
  return {};
}

void DeepHoleDrill::bind_self() {
  pulses.feed(td_);
  gap_.td_us.connect(td_.td_us);
  gap_.valid.connect(td_.valid);
  gap_.tdr_us.follow(tdr_us);
  wear_.vz_in_mm_s.claim();
  wear_.wear_ratio.follow(wear_ratio);
  wear_.area_ratio.follow(area_ratio);
  wear_.enable.follow(enable_wear_comp);
  wear_.reset_wear.claim();
  retract_.z_mm.follow(z_mm);
  retract_.short_detected.claim();
  retract_.enable.claim();
  zloop_.x_ref_mm.connect(retract_.z_sp_mm);
  zloop_.v_ff_mm_s.claim();
  zloop_.x_mm.follow(z_mm);
  zloop_.enable.connect(retract_.active);
}

void DeepHoleDrill::activate_self() noexcept {
  prev_start_ = false;
  spark_cycles_ = 0;
  dark_cycles_ = 0;
  breakthrough.set(false);
  target_depth_mm_ = params_.depth_default_mm;
  retract_to_z_mm_ = 0.0;
  safe_retract_ = false;
  wear_.reset_wear.drive(false);
  wear_.vz_in_mm_s.drive(0.0);
  vz_cmd_mm_s.set(0.0);
  gen_on.set(false);
  depth_reached_mm.set(0.0);
  touch_z_mm.set(0.0);
  wear_mm.set(0.0);
  done.set(false);
  short_pins.reset();
  retract_.enable.drive(false);
  zloop_.v_ff_mm_s.drive(0.0);
  short_time_s.set(0.0);
  guard_.reset();
  set_state(State::kIdle);
}

double DeepHoleDrill::feed_scale() const noexcept {
  const double ov = feed_override.get();
  return std::isfinite(ov) ? std::clamp(ov, 0.0, rt::Machine::kMaxFeedOverride) : 0.0;
}

void DeepHoleDrill::set_state(State s) noexcept {
  state_value_ = s;
  state.set(static_cast<std::int64_t>(s));
}

void DeepHoleDrill::begin_cycle() noexcept {
  const double d = depth_mm.get();
  target_depth_mm_ = d > 0.0 ? d : params_.depth_default_mm;
  const double done_mm = depth_done_mm.get();
  depth_done_mm_ = std::isfinite(done_mm) && done_mm > 0.0 ? done_mm : 0.0;
  const double rz = resume_touch_z_mm.get(), rw = resume_wear_mm.get();
  resume_ = depth_done_mm_ > 0.0 && std::isfinite(rz) && std::isfinite(rw) && rw > 0.0;
  const double cz = contact_z_mm.get(), cd = contact_depth_mm.get();
  measured_ = std::isfinite(cz) && std::isfinite(cd) && cd > 0.0;
  contact_z_mm_ = measured_ ? cz : 0.0;
  contact_depth_mm_ = measured_ ? cd : 0.0;
  if (measured_) {
    resume_ = false;
    depth_done_mm_ = 0.0;
  }
  resume_touch_z_mm_ = resume_ ? rz : 0.0;
  resume_wear_mm_ = resume_ ? rw : 0.0;
  spark_cycles_ = 0;
  dark_cycles_ = 0;
  safe_retract_ = false;
  done.set(false);
  breakthrough.set(false);
  depth_reached_mm.set(0.0);
  wear_mm.set(0.0);
  short_pins.short_retracts.set(0);
  short_time_s.set(0.0);
  guard_.reset();
  set_state(State::kApproach);
}

void DeepHoleDrill::begin_retract(double target_z) noexcept {
  retract_to_z_mm_ = target_z;
  set_state(State::kRetract);
}

void DeepHoleDrill::safe_state_self(const rt::SafeStateRequest& request) noexcept {
  gen_on.set(false);
  retract_.enable.drive(false);
  if (state_value_ == State::kDrill && request.cause == rt::AlarmCode::kShortCircuit) {
    begin_retract(z_mm.get() + params_.short_backoff_mm);  // back off, then hold
    safe_retract_ = true;
  } else if (state_value_ == State::kDrill || state_value_ == State::kBreakthrough) {
    begin_retract(touch_z_mm.get() + params_.clearance_mm);
    safe_retract_ = true;
  } else if (state_value_ == State::kApproach) {
    begin_retract(z_mm.get() + params_.clearance_mm);
    safe_retract_ = true;
  }
  if (state_value_ == State::kRetract) {
    vz_cmd_mm_s.set(params_.retract_speed_mm_s);
  } else {
    vz_cmd_mm_s.set(0.0);
  }
}

bool DeepHoleDrill::handle_short(const rt::CycleContext& ctx, double z,
                                 rt::BlockStatus& status) noexcept {
  const ShortStep s = guard_.step(ctx, td_, retract_, params_.shorts, machine_, source_, short_pins,
                                  [&](rt::Block& child) { return step(child, ctx); });
  status = rt::worst(status, s.status);
  // Alarm 150 without a machine (a unit test): this block backs Z off and holds itself.
  if (s.budget_spent && machine_ == nullptr) {
    safe_state_self({rt::MachineState::kFault, rt::AlarmCode::kShortCircuit});
  }
  if (s.retracting || retract_.v_scale.get() < 1.0) {
    short_time_s.set(short_time_s.get() + ctx.dt_s);
  }
  if (!s.retracting) {
    last_z_sp_mm_ = z;
    return false;
  }
  const double sp = retract_.z_sp_mm.get();
  zloop_.v_ff_mm_s.drive(ctx.dt_s > 0.0 ? (sp - last_z_sp_mm_) / ctx.dt_s : 0.0);
  last_z_sp_mm_ = sp;
  status = rt::worst(status, step(zloop_, ctx));
  return true;
}

rt::BlockStatus DeepHoleDrill::update_self(const rt::CycleContext& ctx) noexcept {
  const bool safe = rt::is_safe_state(ctx.state);
  const bool start_now = start.get();
  const bool rising = start_now && !prev_start_;
  prev_start_ = start_now;
  const double z = z_mm.get();
  const bool comp = enable_wear_comp.get();

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
  if (hold.get() && !safe && (state_value_ == State::kApproach || state_value_ == State::kDrill)) {
    gen_on.set(false);
    vz_cmd_mm_s.set(0.0);
    spark_cycles_ = 0;
    return status;
  }

  bool td_stepped = false;
  if (state_value_ == State::kApproach) {
    status = rt::worst(status, step(td_, ctx));  // fills the Td window before the gap loop starts
    td_stepped = true;
    // A cycle whose own pulses read short has closed the gap too: it counts as a touch, and it
    // feeds no further (the P law then backs off from Td ≈ 0, the short handling from there on).
    const bool shorted = ShortGuard::cycle_reads_short(td_, params_.shorts);
    short_pins.cycle_short.set(shorted);
    short_pins.short_now.set(shorted);
    spark_cycles_ = pulses.td_count.get() > 0 || shorted ? spark_cycles_ + 1 : 0;
    if (spark_cycles_ >= params_.touch_cycles) {
      touch_z_mm.set(measured_ ? contact_z_mm_ : resume_ ? resume_touch_z_mm_ : z);
      wear_.reset_wear.drive(true);  // the wear estimate starts at the touch
      set_state(State::kDrill);
    } else {
      gen_on.set(true);
      vz_cmd_mm_s.set(shorted ? 0.0 : -params_.approach_speed_mm_s * feed_scale());
    }
  }

  if (state_value_ == State::kDrill) {
    if (!td_stepped) {
      status = rt::worst(status, step(td_, ctx));
    }
    status = rt::worst(status, step(gap_, ctx));
    const bool retracting = handle_short(ctx, z, status);
    // Resumed: the hole is already drilled down to depth_done_mm, so no wear is counted (the
    // compensator held at 0) until the front is back where the interrupted drill stopped.
    const bool above_done =
        resume_ && (touch_z_mm.get() - z) - resume_wear_mm_ - params_.spark_gap_offset_um * 1e-3 <
                       depth_done_mm_;
    // Measured: likewise until the front is back one working gap above the measured bottom
    // (it touched contact_offset_um lower than that).
    const bool above_bottom = measured_ && (contact_z_mm_ - z) < -params_.contact_offset_um * 1e-3;
    if (above_done || above_bottom) wear_.reset_wear.drive(true);
    if (!retracting) {
      // The servo's command into the wear compensator: the gap child's Vz, or the external
      // servo's clamped to the gap child's limits; ramped back in after a retract (v_scale
      // 0 → 1), so the compensator sees the feed the axis makes; never down while the window
      // or this cycle's own pulses read short.
      double v = gap_.vz_mm_s.get();
      if (vz_servo_mm_s.connected()) {
        v = vz_servo_mm_s.get();
        if (std::isfinite(v)) {
          v = std::clamp(v, -gap_.params().v_feed_max_mm_s, gap_.params().v_retract_max_mm_s);
        } else {
          v = 0.0;
          status = fault("a non-finite servo feed (vz_servo_mm_s)");
        }
      }
      v *= retract_.v_scale.get();
      v = std::max(v, -gap_.params().v_feed_max_mm_s * feed_scale());  // the override's cap
      wear_.vz_in_mm_s.drive(feed_stopped() ? std::max(v, 0.0) : v);
      status = rt::worst(status, step(wear_, ctx));
      wear_.reset_wear.drive(false);
    }
    // The electrode front is z − accumulated wear: the compensated axis travels further than the
    // front by the length the compensator has added for the wear, so the front has gone
    // (touch_z − z) − wear_mm below the touch point. The front touched at the gap where the
    // first sparks strike and drills one working gap above the bottom: the hole is deeper than
    // the front's travel by the working gap and shallower by the first-spark gap,
    //   depth = (touch_z − z) − wear_mm − spark_gap_offset_um·1e-3   (first-spark − working gap).
    const double wear_now = (comp ? wear_.wear_mm.get() : 0.0) + resume_wear_mm_;
    const double depth = measured_ ? contact_depth_mm_ + (touch_z_mm.get() - z) - wear_now +
                                         params_.contact_offset_um * 1e-3
                                   : (resume_ ? 0.0 : depth_done_mm_) + (touch_z_mm.get() - z) -
                                         wear_now - params_.spark_gap_offset_um * 1e-3;
    depth_reached_mm.set(depth);
    wear_mm.set(wear_now);
    dark_cycles_ = pulses.td_count.get() > 0 ? 0 : dark_cycles_ + 1;
    if (depth >= target_depth_mm_) {
      begin_retract(touch_z_mm.get() + params_.clearance_mm);
    } else if (through.get() && depth >= params_.breakthrough_min_mm &&
               dark_cycles_ >= params_.breakthrough_cycles) {
      breakthrough.set(true);
      breakthrough_z_mm_ = z;
      set_state(State::kBreakthrough);
    } else if (state_value_ == State::kDrill) {
      gen_on.set(true);
      // Retracting: zloop follows the retract's setpoint; else the compensated servo command.
      // While the window or this cycle reads short, never toward the work.
      const double v = retracting ? zloop_.v_cmd_mm_s.get() : wear_.vz_out_mm_s.get();
      vz_cmd_mm_s.set(feed_stopped() ? std::max(v, 0.0) : v);
    }
  }
  if (state_value_ != State::kApproach && state_value_ != State::kDrill) {
    short_pins.clear_now();  // the generator is off: no pulses of this program's
  }
  if (state_value_ != State::kDrill && retract_.enable.driven()) {
    retract_.enable.drive(false);  // the history is the path of this hole's DRILL only
    status = rt::worst(status, step(retract_, ctx));
  }

  if (state_value_ == State::kBreakthrough) {
    gen_on.set(false);
    if (z <= breakthrough_z_mm_ - params_.overtravel_mm) {
      begin_retract(touch_z_mm.get() + params_.clearance_mm);
    } else {
      vz_cmd_mm_s.set(-params_.approach_speed_mm_s * feed_scale());
    }
  }

  if (state_value_ == State::kRetract) {
    gen_on.set(false);
    if (z >= retract_to_z_mm_) {
      vz_cmd_mm_s.set(0.0);
      done.set(!safe_retract_);
      set_state(safe_retract_ ? State::kIdle : State::kDone);
      safe_retract_ = false;
    } else {
      vz_cmd_mm_s.set(params_.retract_speed_mm_s);
    }
  } else if (state_value_ == State::kIdle || state_value_ == State::kDone) {
    gen_on.set(false);
    vz_cmd_mm_s.set(0.0);
  }
  return status;
}

}  // namespace edm::programs
