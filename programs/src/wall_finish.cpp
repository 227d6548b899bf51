#include "edm/programs/wall_finish.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <string_view>

#include "edm/runtime/machine.hpp"

namespace edm::programs {

namespace {

// Indices of the load-time-only parameters in WallFinishParams::visit order.
constexpr std::size_t kSettleIndex = 9;
constexpr std::size_t kTdWindowIndex = 10;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

template <class T>
T get_or(const rt::Output<T>* p, T fallback) noexcept {
  return p != nullptr ? p->get() : fallback;
}

}  // namespace

void WallFinishParams::visit(rt::ParamVisitor& v) {
  v.param("orbit_period_s", orbit_period_s, "s", "time of one orbit revolution (> 0)");
  v.param("radial_speed_mm_s", radial_speed_mm_s, "mm/s",
          "slew rate of the reference orbit radius (> 0)");
  v.param("spark_out_revs", spark_out_revs, "",
          "revolutions at the final radius before returning to the centre (>= 0)");
  v.param("centre_tol_mm", centre_tol_mm, "mm", "BACK ends within this of the centre (> 0)");
  v.param("kr", kr, "mm/us", "orbit growth per revolution per us of mean Td (>= 0)");
  v.param("dr_max_mm", dr_max_mm, "mm", "largest orbit growth per revolution (>= 0)");
  v.param("kv", kv, "1/s", "X/Y position gain (>= 0)");
  v.param("v_max_mm_s", v_max_mm_s, "mm/s", "X/Y velocity command limit (> 0)");
  v.param("f_err_max_mm", f_err_max_mm, "mm", "X/Y following-error limit (> 0)");
  v.param("settle", settle, "s",
          "generator-off time around the polarity switch (> 0), load time only");
  v.param("td_window", td_window, "cycles", "cycles pooled for Td (1..65536), load time only");
  v.param("no_spark_timeout", no_spark_timeout, "s",
          "ORBIT without a spark this long (outside spark-out) is a fault; 0 s: off");
}

std::vector<rt::ParamError> WallFinishParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_positive(errs, "orbit_period_s", orbit_period_s);
  rt::require_positive(errs, "radial_speed_mm_s", radial_speed_mm_s);
  if (spark_out_revs < 0) {
    errs.push_back({"spark_out_revs", "spark_out_revs must be >= 0"});
  }
  rt::require_positive(errs, "centre_tol_mm", centre_tol_mm);
  rt::require_finite(errs, "kr", kr);
  rt::require_non_negative(errs, "kr", kr);
  rt::require_finite(errs, "dr_max_mm", dr_max_mm);
  rt::require_non_negative(errs, "dr_max_mm", dr_max_mm);
  rt::require_finite(errs, "kv", kv);
  rt::require_non_negative(errs, "kv", kv);
  rt::require_positive(errs, "v_max_mm_s", v_max_mm_s);
  rt::require_positive(errs, "f_err_max_mm", f_err_max_mm);
  if (settle <= rt::Duration::zero()) {
    errs.push_back({"settle", "settle must be > 0"});
  }
  if (td_window < 1 || td_window > blocks::TdDetectorParams::kMaxWindow) {
    errs.push_back({"td_window", "td_window must be in 1..65536"});
  }
  if (no_spark_timeout < rt::Duration::zero()) {
    errs.push_back({"no_spark_timeout", "no_spark_timeout must be >= 0"});
  }
  return errs;
}

WallFinish::WallFinish()
    : pol_(add_child<blocks::PolaritySwitch>("pol")),
      td_(add_child<blocks::TdDetector>("td")),
      orbit_(add_child<blocks::OrbitExpander>("orbit")),
      px_(add_child<blocks::PositionLoop>("px")),
      py_(add_child<blocks::PositionLoop>("py")) {}

void WallFinish::visit_own_pins(rt::PinVisitor& v) {
  v.input("td_sum_ns", td_sum_ns_, "ns");
  v.input("td_count", td_count_);
  v.input("n_open", n_open_);
  v.input("n_short", n_short_);
  v.input("x_mm", x_mm_, "mm");
  v.input("y_mm", y_mm_, "mm");
  v.input("start", start_);
  v.input("start_offset_mm", start_offset_mm_, "mm");
  v.input("final_offset_mm", final_offset_mm_, "mm");
  v.input("hold", hold_);
  v.output("no_spark", no_spark_);
  v.output("vx_cmd_mm_s", vx_cmd_mm_s_, "mm/s");
  v.output("vy_cmd_mm_s", vy_cmd_mm_s_, "mm/s");
  v.output("gen_on", gen_on_);
  v.output("polarity_positive", polarity_positive_);
  v.output("state", state_);
  v.output("offset_mm", offset_mm_, "mm");
  v.output("rho_mm", rho_mm_, "mm");
  v.output("revolutions", revolutions_);
  v.output("done", done_);
}

std::vector<rt::ParamError> WallFinish::configure_self(const rt::BlockSetup& setup) {
  // CompositeBlock::configure() has configured the children with their defaults; give them the
  // values derived from our parameters and configure them again (load-time work, harmless).
  std::vector<rt::ParamError> errs;
  blocks::PolaritySwitchParams pp = pol_.params();
  pp.settle = params_.settle;
  pp.initial_positive = false;
  pol_.set_params(pp);
  append_child_errors(errs, "pol", pol_.validate());
  append_child_errors(errs, "pol", pol_.configure(setup));

  blocks::TdDetectorParams tp = td_.params();
  tp.window = params_.td_window;
  td_.set_params(tp);
  append_child_errors(errs, "td", td_.validate());
  append_child_errors(errs, "td", td_.configure(setup));

  params_changed();  // orbit: kr, dr_max; px/py: kv, v_max, f_err
  append_child_errors(errs, "orbit", orbit_.validate());
  append_child_errors(errs, "orbit", orbit_.configure(setup));
  append_child_errors(errs, "px", px_.validate());
  append_child_errors(errs, "px", px_.configure(setup));
  append_child_errors(errs, "py", py_.validate());
  append_child_errors(errs, "py", py_.configure(setup));

  // Internal wires, resolved once.
  wire_child(errs, pol_, "pol", "request_positive", c_pol_req_);
  wire_child(errs, pol_, "pol", "generator_on_request", c_gen_req_);
  pol_positive_ = child_output<bool>(errs, pol_, "pol", "polarity_positive");
  pol_gen_ = child_output<bool>(errs, pol_, "pol", "generator_on");
  pol_switching_ = child_output<bool>(errs, pol_, "pol", "switching");

  wire_child(errs, td_, "td", "td_sum_ns", c_td_sum_ns_);
  wire_child(errs, td_, "td", "td_count", c_td_count_);
  wire_child(errs, td_, "td", "n_open", c_n_open_);
  wire_child(errs, td_, "td", "n_short", c_n_short_);
  const rt::Output<double>* td_us = child_output<double>(errs, td_, "td", "td_us");
  const rt::Output<bool>* td_valid = child_output<bool>(errs, td_, "td", "valid");

  wire_child(errs, orbit_, "orbit", "start", c_orbit_start_);
  wire_child(errs, orbit_, "orbit", "r0_mm", c_r0_);
  wire_child(errs, orbit_, "orbit", "final_radius_mm", c_final_);
  wire_child(errs, orbit_, "orbit", "enable", c_orbit_enable_);
  wire_child(errs, orbit_, "orbit", "rev_pulse", c_rev_pulse_);
  if (td_us != nullptr) {
    wire_child(errs, orbit_, "orbit", "td_us", *td_us);
  }
  if (td_valid != nullptr) {
    wire_child(errs, orbit_, "orbit", "valid", *td_valid);
  }
  orbit_radius_ = child_output<double>(errs, orbit_, "orbit", "radius_mm");
  orbit_done_ = child_output<bool>(errs, orbit_, "orbit", "done");
  orbit_revs_ = child_output<std::int64_t>(errs, orbit_, "orbit", "revolutions");

  wire_child(errs, px_, "px", "x_ref_mm", c_xref_);
  wire_child(errs, px_, "px", "v_ff_mm_s", c_vffx_);
  wire_child(errs, px_, "px", "x_mm", c_x_);
  wire_child(errs, px_, "px", "enable", c_loop_enable_);
  wire_child(errs, py_, "py", "x_ref_mm", c_yref_);
  wire_child(errs, py_, "py", "v_ff_mm_s", c_vffy_);
  wire_child(errs, py_, "py", "x_mm", c_y_);
  wire_child(errs, py_, "py", "enable", c_loop_enable_);
  px_v_ = child_output<double>(errs, px_, "px", "v_cmd_mm_s");
  py_v_ = child_output<double>(errs, py_, "py", "v_cmd_mm_s");
  return errs;
}

void WallFinish::params_changed() noexcept {
  // Plain struct copies (no allocation): RT-safe. The children's parameters are not variables of
  // their own, so nothing reads their shadow copies concurrently.
  blocks::OrbitExpanderParams op = orbit_.params();
  op.kr = params_.kr;
  op.dr_max_mm = params_.dr_max_mm;
  op.samples_per_rev = 0;  // revolutions from rev_pulse
  orbit_.set_params(op);
  for (blocks::PositionLoop* l : {&px_, &py_}) {
    blocks::PositionLoopParams lp = l->params();
    lp.kv = params_.kv;
    lp.v_max_mm_s = params_.v_max_mm_s;
    lp.f_err_max_mm = params_.f_err_max_mm;
    l->set_params(lp);
  }
}

std::vector<rt::ParamError> WallFinish::stage_param(std::size_t index, const rt::ParamValue& v) {
  if (index == kSettleIndex || index == kTdWindowIndex) {
    return {{"", "load time only (set it in the config)"}};
  }
  return BlockWithParams::stage_param(index, v);
}

void WallFinish::activate_self() noexcept {
  prev_start_ = false;
  x0_ = y0_ = 0.0;
  rho_ = theta_ = 0.0;
  revs_ = 0;
  spark_out_left_ = 0;
  spark_out_ = false;
  c_pol_req_.set(false);
  c_gen_req_.set(false);
  c_orbit_start_.set(false);
  c_orbit_enable_.set(false);
  c_rev_pulse_.set(false);
  c_loop_enable_.set(false);
  stop_outputs();
  polarity_positive_.set(get_or(pol_positive_, false));
  offset_mm_.set(0.0);
  rho_mm_.set(0.0);
  revolutions_.set(0);
  done_.set(false);
  set_state(State::kIdle);
}

void WallFinish::set_state(State s) noexcept {
  state_value_ = s;
  state_.set(static_cast<std::int64_t>(s));
}

void WallFinish::stop_outputs() noexcept {
  gen_on_.set(false);
  vx_cmd_mm_s_.set(0.0);
  vy_cmd_mm_s_.set(0.0);
}

void WallFinish::safe_state_self(const rt::SafeStateRequest& /*request*/) noexcept {
  // The children (pol, loops) have had their own safe state; the generator request drops too.
  c_gen_req_.set(false);
  c_loop_enable_.set(false);
  c_orbit_enable_.set(false);
  stop_outputs();
  if (state_value_ != State::kIdle && state_value_ != State::kDone) {
    done_.set(false);
    set_state(State::kIdle);
  }
}

rt::BlockStatus WallFinish::update(const rt::CycleContext& ctx) noexcept {
  const bool safe = rt::is_safe_state(ctx.state);
  const bool start = start_.get();
  const bool rising = start && !prev_start_;
  prev_start_ = start;
  const double x = x_mm_.get();
  const double y = y_mm_.get();
  const double dt = ctx.dt_s;

  c_td_sum_ns_.set(td_sum_ns_.get());
  c_td_count_.set(td_count_.get());
  c_n_open_.set(n_open_.get());
  c_n_short_.set(n_short_.get());
  c_x_.set(x);
  c_y_.set(y);

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
    no_spark_.set(false);
    const double r0 = start_offset_mm_.get();
    c_r0_.set(r0);
    c_final_.set(std::max(final_offset_mm_.get(), r0));
    c_pol_req_.set(true);
    done_.set(false);
    revolutions_.set(0);
    set_state(State::kPolarity);
  }

  // Feed hold in the orbit: generator off, the reference stays where it is (the loops hold the
  // electrode still), the phase, radius, Td window and revolution count wait.
  const bool held = hold_.get() && !safe && state_value_ == State::kOrbit;

  // The polarity switch runs every cycle (it times the generator-off periods).
  c_gen_req_.set(state_value_ == State::kOrbit && !safe && !held);
  status = rt::worst(status, pol_.update(ctx));
  const bool positive = get_or(pol_positive_, false);
  polarity_positive_.set(positive);

  if (state_value_ == State::kPolarity && positive && !get_or(pol_switching_, true)) {
    c_orbit_start_.set(true);  // rising edge for the orbit child: latches r0 and final
    c_orbit_enable_.set(false);
    c_rev_pulse_.set(false);
    c_gen_req_.set(true);
    set_state(State::kOrbit);
  }

  double rho_target = 0.0;
  if (held) {
    rho_target = rho_;
  } else if (state_value_ == State::kOrbit) {
    status = rt::worst(status, td_.update(ctx));
    dark_s_ = td_count_.get() > 0 || n_short_.get() > 0 ? 0.0 : dark_s_ + dt;
    if (!spark_out_ && params_.no_spark_timeout > rt::Duration::zero() &&
        dark_s_ >= rt::to_seconds(params_.no_spark_timeout)) {
      no_spark_.set(true);  // the task raises the block-fault alarm: safe state, job aborted
      status = rt::BlockStatus::kFault;
    }
    const double radius = get_or(orbit_radius_, 0.0);
    // Revolutions count (and Td is collected) only once the reference radius has reached the
    // orbit radius: the entry from the centre is not a machining revolution.
    const bool on_radius = rho_ == radius;
    const double prev_theta = theta_;
    theta_ += kTwoPi * dt / params_.orbit_period_s;
    bool wrapped = false;
    if (theta_ >= kTwoPi) {
      theta_ -= kTwoPi;
      wrapped = prev_theta < kTwoPi;
    }
    c_orbit_enable_.set(on_radius);
    c_rev_pulse_.set(wrapped && on_radius);
    if (wrapped && on_radius) {
      ++revs_;
      if (spark_out_ && spark_out_left_ > 0) {
        --spark_out_left_;
      }
    }
    status = rt::worst(status, orbit_.update(ctx));
    c_orbit_start_.set(false);
    if (!spark_out_ && get_or(orbit_done_, false) && get_or(orbit_radius_, 0.0) == rho_) {
      spark_out_ = true;  // the final radius is reached: spark out for spark_out_revs more
    }
    offset_mm_.set(get_or(orbit_radius_, 0.0));
    revolutions_.set(revs_);
    if (spark_out_ && spark_out_left_ == 0) {
      set_state(State::kBack);
    } else {
      rho_target = get_or(orbit_radius_, 0.0);
    }
  }

  if (state_value_ == State::kOrbit || state_value_ == State::kBack) {
    // Slew the reference radius toward its target, then place the reference point.
    const double step = params_.radial_speed_mm_s * dt;
    rho_ =
        rho_ < rho_target ? std::min(rho_ + step, rho_target) : std::max(rho_ - step, rho_target);
    const double xr = x0_ + rho_ * std::cos(theta_);
    const double yr = y0_ + rho_ * std::sin(theta_);
    const double vffx = dt > 0.0 ? (xr - c_xref_.get()) / dt : 0.0;
    const double vffy = dt > 0.0 ? (yr - c_yref_.get()) / dt : 0.0;
    c_xref_.set(xr);
    c_yref_.set(yr);
    c_vffx_.set(vffx);
    c_vffy_.set(vffy);
    c_loop_enable_.set(true);
    status = rt::worst(status, px_.update(ctx));
    status = rt::worst(status, py_.update(ctx));
    vx_cmd_mm_s_.set(get_or(px_v_, 0.0));
    vy_cmd_mm_s_.set(get_or(py_v_, 0.0));
    rho_mm_.set(rho_);
  }

  if (state_value_ == State::kBack) {
    c_gen_req_.set(false);
    if (rho_ == 0.0 && std::hypot(x - x0_, y - y0_) <= params_.centre_tol_mm) {
      set_state(State::kDone);
      done_.set(true);
    }
  }

  if (state_value_ == State::kOrbit && !held) {
    gen_on_.set(get_or(pol_gen_, false));
  } else {
    gen_on_.set(false);
  }
  if (state_value_ != State::kOrbit && state_value_ != State::kBack) {
    c_loop_enable_.set(false);
    c_xref_.set(x);
    c_yref_.set(y);
    vx_cmd_mm_s_.set(0.0);
    vy_cmd_mm_s_.set(0.0);
  }
  if (state_value_ == State::kDone) {
    // Hold the reference at the centre so that a restart begins there.
    c_xref_.set(x0_);
    c_yref_.set(y0_);
  }
  return status;
}

}  // namespace edm::programs
