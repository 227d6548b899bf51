#include "edm/programs/wall_finish.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <string_view>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/machine.hpp"

namespace edm::programs {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kMinBaseRadiusMm = 1e-3;  // the arc's radius when the final offset is ~0
constexpr double kCentreRadiusMm = 1e-6;   // closer to the hole centre: no radial direction

}  // namespace

void WallFinishParams::visit(rt::ParamVisitor& v) {
  namespace r = blocks::ranges;  // the shared physical ranges (param_ranges.hpp)
  // Ranges (issue 31): the orbit feed up to 60 m/min (1 m/s, as any axis speed); spark-out up to
  // 1e6 revolutions; the rest in param_ranges.hpp.
  v.param("feed_default_mm_min", feed_default_mm_min,
          {"mm/min",
           "orbit feed fr along the arc's radius (the final offset) while the feed_mm_min input is "
           "<= 0",
           rt::open_closed(0.0, 60000.0)});
  v.param("radial_speed_mm_s", radial_speed_mm_s,
          {"mm/s", "slew rate of the reference orbit radius", r::kSpeedMmS});
  v.param("spark_out_revs", spark_out_revs,
          {"", "revolutions at the final radius before returning to the centre",
           rt::closed(0.0, 1.0e6)});
  v.param("centre_tol_mm", centre_tol_mm,
          {"mm", "BACK ends within this of the centre", r::kPositiveToleranceMm});
  v.param("no_spark_timeout", no_spark_timeout,
          {"s", "ORBIT without a spark this long (outside spark-out) is a fault; 0 s: off",
           r::kProcessTimeS});
  shorts.visit(v);
}

WallFinish::WallFinish()
    : pol_(add_child<blocks::PolaritySwitch>("pol")),
      td_(add_child<blocks::TdDetector>("td")),
      orbit_(add_child<blocks::OrbitExpander>("orbit")),
      arc_(add_child<blocks::CircularInterpolator>("arc")),
      px_(add_child<blocks::PositionLoop>("px")),
      py_(add_child<blocks::PositionLoop>("py")),
      retract_(add_child<blocks::ShortRetract>("retract")) {
  // This program's defaults for its children (variables of their own, set in YAML).
  blocks::PolaritySwitchParams pp;
  pp.initial_positive = false;
  pol_.set_params(pp);
  blocks::OrbitExpanderParams op;
  op.kr = 0.0001;
  // Eq. 21 live: Td ≤ the open threshold (100 µs on the presets) keeps kr·Tdm ≤ 0.01 mm, so this
  // limit only guards against a misconfigured kr (it clamped every step at 0.002 before issue 20).
  op.dr_max_mm = 0.01;
  op.samples_per_rev = 0;  // revolutions from rev_pulse
  orbit_.set_params(op);
  for (blocks::PositionLoop* l : {&px_, &py_}) {
    blocks::PositionLoopParams lp;
    lp.v_max_mm_s = 5.0;
    l->set_params(lp);
  }
  blocks::ShortRetractParams rp;
  rp.short_cycles = 5;           // with td.window: the detection window
  rp.max_tries = 1000;           // the retract budget is this program's
  rp.retract_distance_mm = 0.2;  // along the contour
  rp.retract_speed_mm_s = 2.0;   // within the loops' 5 mm/s
  rp.resume_speed_mm_s = 1.0;
  retract_.set_params(rp);
}

std::vector<rt::ParamError> WallFinish::configure_self(const rt::BlockSetup& setup) {
  machine_ = setup.machine;
  source_ = std::string(setup.instance);
  if (orbit_.params().samples_per_rev != 0) {
    return {{"orbit.samples_per_rev",
             "must be 0 in WallFinish (revolutions come from the orbit phase)"}};
  }
  return {};
}

void WallFinish::bind_self() {
  pulses.feed(td_);
  orbit_.td_us.connect(td_.td_us);
  orbit_.valid.connect(td_.valid);
  arc_.j_mm.set_constant(0.0);
  arc_.cw.set_constant(false);  // G03
  arc_.full_circle.set_constant(true);
  arc_.turns.set_constant(blocks::CircularInterpolator::kMaxTurns);
  arc_.feed_override.follow(feed_override);
  px_.x_mm.follow(x_mm);
  py_.x_mm.follow(y_mm);
  // Driven each cycle by the sequence (Input::drive).
  for (rt::Input<bool>* in :
       {&pol_.request_positive, &pol_.generator_on_request, &orbit_.start, &orbit_.enable,
        &orbit_.rev_pulse, &arc_.start, &arc_.load, &px_.enable, &py_.enable}) {
    in->claim();
  }
  for (rt::Input<double>* in :
       {&orbit_.r0_mm, &orbit_.final_radius_mm, &arc_.load_x_mm, &arc_.load_y_mm, &arc_.i_mm,
        &arc_.feed_mm_min, &px_.x_ref_mm, &px_.v_ff_mm_s, &py_.x_ref_mm, &py_.v_ff_mm_s,
        &retract_.x_mm, &retract_.y_mm}) {  // retract: the contour as commanded
    in->claim();
  }
}

void WallFinish::activate_self() noexcept {
  prev_start_ = false;
  x0_ = y0_ = 0.0;
  rho_ = theta_ = r_base_ = 0.0;
  arc_turns_ = 0;
  arc_.start.drive(false);
  arc_.load.drive(false);
  revs_ = 0;
  spark_out_left_ = 0;
  spark_out_ = false;
  pol_.request_positive.drive(false);
  pol_.generator_on_request.drive(false);
  orbit_.start.drive(false);
  orbit_.enable.drive(false);
  orbit_.rev_pulse.drive(false);
  enable_loops(false);
  stop_outputs();
  polarity_positive.set(pol_.polarity_positive.get());
  offset_mm.set(0.0);
  rho_mm.set(0.0);
  revolutions.set(0);
  done.set(false);
  short_pins.reset();
  retract_.enable.drive(false);
  guard_.reset();
  set_state(State::kIdle);
}

void WallFinish::set_state(State s) noexcept {
  state_value_ = s;
  state.set(static_cast<std::int64_t>(s));
}

void WallFinish::stop_outputs() noexcept {
  gen_on.set(false);
  vx_cmd_mm_s.set(0.0);
  vy_cmd_mm_s.set(0.0);
}

void WallFinish::set_reference(double x, double y) noexcept {
  x_ref_ = x;
  y_ref_ = y;
  px_.x_ref_mm.drive(x);
  py_.x_ref_mm.drive(y);
  retract_.x_mm.drive(x);
  retract_.y_mm.drive(y);
}

void WallFinish::enable_loops(bool on) noexcept {
  px_.enable.drive(on);
  py_.enable.drive(on);
}

void WallFinish::safe_state_self(const rt::SafeStateRequest& /*request*/) noexcept {
  // The children (pol, loops) have had their own safe state; the generator request drops too.
  pol_.generator_on_request.drive(false);
  enable_loops(false);
  orbit_.enable.drive(false);
  stop_outputs();
  if (state_value_ != State::kIdle && state_value_ != State::kDone) {
    done.set(false);
    set_state(State::kIdle);
  }
}

bool WallFinish::handle_short(const rt::CycleContext& ctx, rt::BlockStatus& status) noexcept {
  const ShortStep s = guard_.step(ctx, td_, retract_, params_.shorts, machine_, source_.c_str(),
                                  short_pins, [&](rt::Block& child) { return step(child, ctx); });
  status = rt::worst(status, s.status);
  // Alarm 150 without a machine (a unit test): this block stops the orbit itself.
  if (s.budget_spent && machine_ == nullptr) {
    safe_state_self({rt::MachineState::kFault, rt::AlarmCode::kShortCircuit});
  }
  return s.retracting;
}

rt::BlockStatus WallFinish::update_self(const rt::CycleContext& ctx) noexcept {
  const bool safe = rt::is_safe_state(ctx.state);
  const bool start_now = start.get();
  const bool rising = start_now && !prev_start_;
  prev_start_ = start_now;
  const double x = x_mm.get();
  const double y = y_mm.get();
  const double dt = ctx.dt_s;

  if (safe && state_value_ != State::kIdle && state_value_ != State::kDone) {
    // Normally done by safe_state_self(); kept here so no path can orbit in a safe state.
    safe_state_self(rt::SafeStateRequest{});
  }

  rt::BlockStatus status = rt::BlockStatus::kOk;
  if ((state_value_ == State::kIdle || state_value_ == State::kDone) && rising && !safe) {
    x0_ = x;
    y0_ = y;
    rho_ = 0.0;
    theta_ = 0.0;
    revs_ = 0;
    spark_out_ = false;
    spark_out_left_ = params_.spark_out_revs;
    dark_s_ = 0.0;
    no_spark.set(false);
    const double r0 = start_offset_mm.get();
    orbit_.r0_mm.drive(r0);
    orbit_.final_radius_mm.drive(std::max(final_offset_mm.get(), r0));
    pol_.request_positive.drive(true);
    done.set(false);
    revolutions.set(0);
    set_state(State::kPolarity);
  }

  // Feed hold in the orbit: generator off, the reference stays where it is (the loops hold the
  // electrode still), the phase, radius, Td window and revolution count wait.
  const bool held = hold.get() && !safe && state_value_ == State::kOrbit;

  // The polarity switch runs every cycle (it times the generator-off periods).
  pol_.generator_on_request.drive(state_value_ == State::kOrbit && !safe && !held);
  status = rt::worst(status, step(pol_, ctx));
  const bool positive = pol_.polarity_positive.get();
  polarity_positive.set(positive);

  if (state_value_ == State::kPolarity && positive && !pol_.switching.get()) {
    orbit_.start.drive(true);  // rising edge for the orbit child: latches r0 and final
    orbit_.enable.drive(false);
    orbit_.rev_pulse.drive(false);
    pol_.generator_on_request.drive(true);
    // The arc: full circles of radius R_b (the final offset) about the centre, from angle 0.
    r_base_ = std::max(orbit_.final_radius_mm.driven(), kMinBaseRadiusMm);
    arc_.load_x_mm.drive(x0_ + r_base_);
    arc_.load_y_mm.drive(y0_);
    arc_.i_mm.drive(-r_base_);
    const double fr = feed_mm_min.get();
    arc_.feed_mm_min.drive(fr > 0.0 && std::isfinite(fr) ? fr : params_.feed_default_mm_min);
    arc_.load.drive(true);
    arc_.start.drive(false);
    status = rt::worst(status, step(arc_, ctx));  // at the load point
    arc_.load.drive(false);
    arc_turns_ = 0;
    theta_ = 0.0;
    set_state(State::kOrbit);
  }

  double rho_target = 0.0;
  bool retracting = false;
  if (held) {
    rho_target = rho_;
  } else if (state_value_ == State::kOrbit) {
    status = rt::worst(status, step(td_, ctx));
    dark_s_ = pulses.td_count.get() > 0 || pulses.n_short.get() > 0 ? 0.0 : dark_s_ + dt;
    if (!spark_out_ && params_.no_spark_timeout > rt::Duration::zero() &&
        dark_s_ >= rt::to_seconds(params_.no_spark_timeout)) {
      no_spark.set(true);  // the task raises the block-fault alarm: safe state, job aborted
      status = fault(
          "no spark for no_spark_timeout while orbiting: the electrode does not reach "
          "the wall (worn shorter than the job assumed, or a wrong offset)",
          dark_s_);
    }
    retracting = handle_short(ctx, status);
    if (retracting || short_pins.short_now.get()) {
      rho_target = rho_;  // a short: the phase and the radius wait
    } else {
      const double radius = orbit_.radius_mm.get();
      // Revolutions count (and Td is collected) only once the reference radius has reached the
      // orbit radius: the entry from the centre is not a machining revolution.
      const bool on_radius = rho_ == radius;
      arc_.start.drive(true);  // a rising edge the first time: the arc latches its circle
      status = rt::worst(status, step(arc_, ctx));
      theta_ = arc_.angle_rad.get();
      const auto turns_done = static_cast<std::int64_t>(std::floor(arc_.swept_rad.get() / kTwoPi));
      const bool wrapped = turns_done > arc_turns_;
      arc_turns_ = turns_done;
      orbit_.enable.drive(on_radius);
      orbit_.rev_pulse.drive(wrapped && on_radius);
      if (wrapped && on_radius) {
        ++revs_;
        if (spark_out_ && spark_out_left_ > 0) {
          --spark_out_left_;
        }
      }
      status = rt::worst(status, step(orbit_, ctx));
      orbit_.start.drive(false);
      if (!spark_out_ && orbit_.done.get() && orbit_.radius_mm.get() == rho_) {
        spark_out_ = true;  // the final radius is reached: spark out for spark_out_revs more
      }
      offset_mm.set(orbit_.radius_mm.get());
      revolutions.set(revs_);
      if (spark_out_ && spark_out_left_ == 0) {
        set_state(State::kBack);
      } else {
        rho_target = orbit_.radius_mm.get();
      }
    }
  }
  if (state_value_ != State::kOrbit) {
    short_pins.clear_now();  // the generator is off outside the orbit
  }
  if (state_value_ != State::kOrbit && retract_.enable.driven()) {
    retract_.enable.drive(false);  // the history is this orbit's contour only
    status = rt::worst(status, step(retract_, ctx));
  }

  if (state_value_ == State::kOrbit || state_value_ == State::kBack) {
    double xr = 0.0;
    double yr = 0.0;
    if (retracting) {
      xr = retract_.x_sp_mm.get();  // back along the contour, and forward again
      yr = retract_.y_sp_mm.get();
    } else {
      // Slew the reference radius toward its target, then place the reference point.
      const double slew = params_.radial_speed_mm_s * dt;
      rho_ =
          rho_ < rho_target ? std::min(rho_ + slew, rho_target) : std::max(rho_ - slew, rho_target);
      // Fig. 1: the interpolator's point, plus the orbit compensation along the radius.
      xr = arc_.rx_mm.get() + (rho_ - r_base_) * std::cos(theta_);
      yr = arc_.ry_mm.get() + (rho_ - r_base_) * std::sin(theta_);
    }
    px_.v_ff_mm_s.drive(dt > 0.0 ? (xr - x_ref_) / dt : 0.0);
    py_.v_ff_mm_s.drive(dt > 0.0 ? (yr - y_ref_) / dt : 0.0);
    set_reference(xr, yr);
    enable_loops(true);
    status = rt::worst(status, step(px_, ctx));
    status = rt::worst(status, step(py_, ctx));
    double vx = px_.v_cmd_mm_s.get();
    double vy = py_.v_cmd_mm_s.get();
    if (state_value_ == State::kOrbit && short_pins.short_now.get()) {
      // Reading short: nothing toward the wall, i.e. no outward part along the electrode's
      // radius from the hole centre (at the centre itself, where every way is outward: stop).
      const double rx = x - x0_, ry = y - y0_;
      const double r = std::hypot(rx, ry);
      if (!(r > kCentreRadiusMm)) {
        vx = vy = 0.0;
      } else {
        const double out = (vx * rx + vy * ry) / r;
        if (out > 0.0) {
          vx -= out * rx / r;
          vy -= out * ry / r;
        }
      }
    }
    vx_cmd_mm_s.set(vx);
    vy_cmd_mm_s.set(vy);
    rho_mm.set(rho_);
  }

  if (state_value_ == State::kBack) {
    pol_.generator_on_request.drive(false);
    if (rho_ == 0.0 && std::hypot(x - x0_, y - y0_) <= params_.centre_tol_mm) {
      set_state(State::kDone);
      done.set(true);
    }
  }

  if (state_value_ == State::kOrbit && !held) {
    gen_on.set(pol_.generator_on.get());
  } else {
    gen_on.set(false);
  }
  if (state_value_ != State::kOrbit && state_value_ != State::kBack) {
    enable_loops(false);
    set_reference(x, y);
    vx_cmd_mm_s.set(0.0);
    vy_cmd_mm_s.set(0.0);
  }
  if (state_value_ == State::kDone) {
    // Hold the reference at the centre so that a restart begins there.
    set_reference(x0_, y0_);
  }
  return status;
}

}  // namespace edm::programs
