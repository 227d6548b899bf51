#include "edm/programs/edm_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "edm/runtime/machine.hpp"

namespace edm::programs {
namespace {
using machining::MotionBlock;
using machining::MotionKind;
}  // namespace

void EdmJobParams::visit(rt::ParamVisitor& v) {
  v.param("rapid_speed_mm_s", rapid_speed_mm_s, "mm/s", "speed of rapids (> 0)");
  v.param("feed_default_mm_s", feed_default_mm_s, "mm/s",
          "feed of linear moves and arcs whose block has none (> 0)");
  v.param("orbit_radius_offset_mm", orbit_radius_offset_mm, "mm",
          "orbit offset = final radius - this (electrode radius + finishing side gap, > 0)");
  v.param("polarity_settle", polarity_settle, "",
          "generator-off wait when a condition changes the polarity (>= 0)");
  v.param("kv", kv, "1/s", "position gain of the X/Y/Z loops (> 0)");
  v.param("f_err_max_mm", f_err_max_mm, "mm", "following-error limit of the loops (> 0)");
}

std::vector<rt::ParamError> EdmJobParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_positive(errs, "rapid_speed_mm_s", rapid_speed_mm_s);
  rt::require_positive(errs, "feed_default_mm_s", feed_default_mm_s);
  rt::require_positive(errs, "orbit_radius_offset_mm", orbit_radius_offset_mm);
  if (polarity_settle.count() < 0) {
    errs.push_back({"polarity_settle", "polarity_settle must be >= 0"});
  }
  rt::require_positive(errs, "kv", kv);
  rt::require_positive(errs, "f_err_max_mm", f_err_max_mm);
  return errs;
}

EdmJob::EdmJob()
    : drill_(add_child<DeepHoleDrill>("drill")),
      finish_(add_child<WallFinish>("finish")),
      lin_(add_child<blocks::LinearInterpolator>("lin")),
      arc_(add_child<blocks::CircularInterpolator>("arc")),
      px_(add_child<blocks::PositionLoop>("px")),
      py_(add_child<blocks::PositionLoop>("py")),
      pz_(add_child<blocks::PositionLoop>("pz")) {}

void EdmJob::visit_own_pins(rt::PinVisitor& v) {
  v.input("td_sum_ns", td_sum_ns_, "ns");
  v.input("td_count", td_count_);
  v.input("n_open", n_open_);
  v.input("n_short", n_short_);
  v.input("n_normal", n_normal_);
  v.input("n_transient_arc", n_transient_arc_);
  v.input("n_stable_arc", n_stable_arc_);
  v.input("x_mm", x_mm_, "mm");
  v.input("y_mm", y_mm_, "mm");
  v.input("z_mm", z_mm_, "mm");
  v.output("vx_cmd_mm_s", vx_, "mm/s");
  v.output("vy_cmd_mm_s", vy_, "mm/s");
  v.output("vz_cmd_mm_s", vz_, "mm/s");
  v.output("gen_arm", gen_arm_);
  v.output("gen_on", gen_on_);
  v.output("polarity_positive", polarity_positive_);
  v.output("flushing_on", flushing_on_);
  v.output("rotation_on", rotation_on_);
  v.output("on_time_us", on_time_us_, "us");
  v.output("off_time_us", off_time_us_, "us");
  v.output("servo_ref_v", servo_ref_v_, "V");
  v.output("state", state_);
  v.output("block_index", block_index_);
  v.output("line", line_);
  v.output("jobs_finished", jobs_finished_);
  v.output("job_time_s", job_time_s_, "s");
  v.output("job_pulses", job_pulses_);
  v.output("job_shorts", job_shorts_);
  v.output("job_arcs", job_arcs_);
  v.output("job_depth_mm", job_depth_mm_, "mm");
  v.output("job_wear_mm", job_wear_mm_, "mm");
}

std::vector<rt::ParamError> EdmJob::configure_self(const rt::BlockSetup& setup) {
  std::vector<rt::ParamError> errs;
  machine_ = setup.machine;
  job_ = setup.job;
  if (job_ != nullptr) job_->attach_runner();
  tables_ = setup.tables;
  if (machine_ == nullptr || job_ == nullptr || tables_ == nullptr) {
    errs.push_back({"", "EdmJob needs the runtime's machine, job store and tables"});
    return errs;
  }
  params_changed();
  // The finishing child with the orbit settings calibrated on the simulator's drill preset
  // (config/machines/finish-sim-program.yaml): Δr clamp 2 µm, kr 1e-4 mm/µs, 4 spark-out turns.
  WallFinishParams fp = finish_.params();
  fp.kr = 0.0001;
  fp.dr_max_mm = 0.002;
  fp.spark_out_revs = 4;
  finish_.set_params(fp);
  append_child_errors(errs, "finish", finish_.validate());
  append_child_errors(errs, "finish", finish_.configure(setup));
  for (blocks::PositionLoop* p : {&px_, &py_, &pz_}) {
    append_child_errors(errs, "p", p->validate());
    append_child_errors(errs, "p", p->configure(setup));
  }
  // Sensors and counters into the children.
  for (auto [child, name] : {std::pair<rt::Block*, const char*>{&drill_, "drill"},
                             std::pair<rt::Block*, const char*>{&finish_, "finish"}}) {
    wire_child(errs, *child, name, "td_sum_ns", c_td_sum_ns_);
    wire_child(errs, *child, name, "td_count", c_td_count_);
    wire_child(errs, *child, name, "n_open", c_n_open_);
    wire_child(errs, *child, name, "n_short", c_n_short_);
  }
  wire_child(errs, drill_, "drill", "z_mm", c_z_);
  wire_child(errs, drill_, "drill", "start", c_drill_start_);
  wire_child(errs, drill_, "drill", "depth_mm", c_depth_);
  wire_child(errs, drill_, "drill", "wear_ratio", c_wear_ratio_);
  wire_child(errs, drill_, "drill", "tdr_us", c_tdr_);
  wire_child(errs, drill_, "drill", "through", c_through_);
  wire_child(errs, drill_, "drill", "hold", c_hold_);
  wire_child(errs, finish_, "finish", "hold", c_hold_);  // one hold for either child
  wire_child(errs, finish_, "finish", "x_mm", c_x_);
  wire_child(errs, finish_, "finish", "y_mm", c_y_);
  wire_child(errs, finish_, "finish", "start", c_finish_start_);
  wire_child(errs, finish_, "finish", "final_offset_mm", c_final_offset_);
  wire_child(errs, finish_, "finish", "start_offset_mm", c_start_offset_);
  drill_vz_ = child_output<double>(errs, drill_, "drill", "vz_cmd_mm_s");
  drill_gen_ = child_output<bool>(errs, drill_, "drill", "gen_on");
  drill_state_ = child_output<std::int64_t>(errs, drill_, "drill", "state");
  drill_depth_ = child_output<double>(errs, drill_, "drill", "depth_reached_mm");
  drill_wear_ = child_output<double>(errs, drill_, "drill", "wear_mm");
  finish_vx_ = child_output<double>(errs, finish_, "finish", "vx_cmd_mm_s");
  finish_vy_ = child_output<double>(errs, finish_, "finish", "vy_cmd_mm_s");
  finish_gen_ = child_output<bool>(errs, finish_, "finish", "gen_on");
  finish_pos_ = child_output<bool>(errs, finish_, "finish", "polarity_positive");
  finish_state_ = child_output<std::int64_t>(errs, finish_, "finish", "state");
  // Interpolators.
  wire_child(errs, lin_, "lin", "start", c_lin_start_);
  wire_child(errs, lin_, "lin", "hold", c_lin_hold_);
  wire_child(errs, lin_, "lin", "load", c_lin_load_);
  wire_child(errs, lin_, "lin", "load_x_mm", c_x_);
  wire_child(errs, lin_, "lin", "load_y_mm", c_y_);
  wire_child(errs, lin_, "lin", "load_z_mm", c_z_);
  wire_child(errs, lin_, "lin", "lx_mm", c_lx_);
  wire_child(errs, lin_, "lin", "ly_mm", c_ly_);
  wire_child(errs, lin_, "lin", "lz_mm", c_lz_);
  wire_child(errs, lin_, "lin", "feed_mm_min", c_lin_feed_);
  wire_child(errs, arc_, "arc", "start", c_arc_start_);
  wire_child(errs, arc_, "arc", "hold", c_arc_hold_);
  wire_child(errs, arc_, "arc", "load", c_arc_load_);
  wire_child(errs, arc_, "arc", "load_x_mm", c_x_);
  wire_child(errs, arc_, "arc", "load_y_mm", c_y_);
  wire_child(errs, arc_, "arc", "cw", c_arc_cw_);
  wire_child(errs, arc_, "arc", "full_circle", c_arc_full_);
  wire_child(errs, arc_, "arc", "turns", c_turns_);
  wire_child(errs, arc_, "arc", "i_mm", c_i_);
  wire_child(errs, arc_, "arc", "j_mm", c_j_);
  wire_child(errs, arc_, "arc", "ex_mm", c_ex_);
  wire_child(errs, arc_, "arc", "ey_mm", c_ey_);
  wire_child(errs, arc_, "arc", "feed_mm_min", c_arc_feed_);
  lin_rx_ = child_output<double>(errs, lin_, "lin", "rx_mm");
  lin_ry_ = child_output<double>(errs, lin_, "lin", "ry_mm");
  lin_rz_ = child_output<double>(errs, lin_, "lin", "rz_mm");
  lin_vx_ = child_output<double>(errs, lin_, "lin", "vx_mm_s");
  lin_vy_ = child_output<double>(errs, lin_, "lin", "vy_mm_s");
  lin_vz_ = child_output<double>(errs, lin_, "lin", "vz_mm_s");
  lin_done_ = child_output<bool>(errs, lin_, "lin", "done");
  arc_rx_ = child_output<double>(errs, arc_, "arc", "rx_mm");
  arc_ry_ = child_output<double>(errs, arc_, "arc", "ry_mm");
  arc_vx_ = child_output<double>(errs, arc_, "arc", "vx_mm_s");
  arc_vy_ = child_output<double>(errs, arc_, "arc", "vy_mm_s");
  arc_done_ = child_output<bool>(errs, arc_, "arc", "done");
  // Loops.
  const std::pair<blocks::PositionLoop*, const char*> loops[] = {
      {&px_, "px"}, {&py_, "py"}, {&pz_, "pz"}};
  rt::Output<double>* refs[] = {&c_xref_, &c_yref_, &c_zref_};
  rt::Output<double>* ffs[] = {&c_vffx_, &c_vffy_, &c_vffz_};
  rt::Output<double>* pos[] = {&c_x_, &c_y_, &c_z_};
  const rt::Output<double>** vs[] = {&px_v_, &py_v_, &pz_v_};
  const rt::Output<bool>** inpos[] = {&px_inpos_, &py_inpos_, &pz_inpos_};
  const rt::Output<bool>** ferr[] = {&px_ferr_, &py_ferr_, &pz_ferr_};
  for (std::size_t k = 0; k < 3; ++k) {
    auto [loop, name] = loops[k];
    wire_child(errs, *loop, name, "x_ref_mm", *refs[k]);
    wire_child(errs, *loop, name, "v_ff_mm_s", *ffs[k]);
    wire_child(errs, *loop, name, "x_mm", *pos[k]);
    wire_child(errs, *loop, name, "enable", c_loop_enable_);
    *vs[k] = child_output<double>(errs, *loop, name, "v_cmd_mm_s");
    *inpos[k] = child_output<bool>(errs, *loop, name, "in_position");
    *ferr[k] = child_output<bool>(errs, *loop, name, "following_error_fault");
  }
  name_ = "job";
  return errs;
}

void EdmJob::params_changed() noexcept {
  for (blocks::PositionLoop* p : {&px_, &py_, &pz_}) {
    blocks::PositionLoopParams lp = p->params();
    lp.kv = params_.kv;
    lp.f_err_max_mm = params_.f_err_max_mm;
    lp.v_max_mm_s = std::max(params_.rapid_speed_mm_s * 1.5, lp.v_max_mm_s);
    p->set_params(lp);
  }
}

void EdmJob::activate_self() noexcept {
  state_value_ = State::kIdle;
  hold_valid_ = false;
  step_ = Step::kEnter;
  condition_ = nullptr;
  polarity_positive_value_ = false;
  limit_alarm_raised_ = false;
  stop_outputs();
  gen_arm_.set(false);
  flushing_on_.set(false);
  rotation_on_.set(false);
  state_.set(0);
  jobs_finished_.set(0);
}

void EdmJob::stop_outputs() noexcept {
  vx_.set(0.0);
  vy_.set(0.0);
  vz_.set(0.0);
  gen_on_.set(false);
  c_drill_start_.set(false);
  c_finish_start_.set(false);
  c_lin_start_.set(false);
  c_arc_start_.set(false);
}

void EdmJob::safe_state_self(const rt::SafeStateRequest& /*request*/) noexcept {
  // The children back Z off (drill) and stop the orbit (finish); the job ends.
  gen_on_.set(false);
  gen_arm_.set(false);
  if (state_value_ == State::kRun) finish_job(rt::JobOutcome::kAborted);
}

void EdmJob::finish_job(rt::JobOutcome outcome) noexcept {
  if (job_ != nullptr) job_->rt_finish(outcome);
  drill_returning_ = false;
  if (outcome == rt::JobOutcome::kFinished) jobs_finished_.set(jobs_finished_.get() + 1);
  state_value_ = State::kIdle;
  state_.set(0);
  step_ = Step::kEnter;
  c_drill_start_.set(false);
  c_hold_.set(false);
  c_finish_start_.set(false);
  gen_arm_.set(false);
  gen_on_.set(false);
}

void EdmJob::begin_job_figures(const rt::CycleContext& ctx) noexcept {
  job_start_ = ctx.release;
  wear_before_block_ = 0.0;
  job_time_s_.set(0.0);
  job_pulses_.set(0);
  job_shorts_.set(0);
  job_arcs_.set(0);
  job_depth_mm_.set(0.0);
  job_wear_mm_.set(0.0);
}

void EdmJob::count_job_figures(const rt::CycleContext& ctx) noexcept {
  job_time_s_.set(std::chrono::duration<double>(ctx.release - job_start_).count());
  const std::int64_t arcs = n_transient_arc_.get() + n_stable_arc_.get();
  job_pulses_.set(job_pulses_.get() + n_open_.get() + n_normal_.get() + arcs + n_short_.get());
  job_shorts_.set(job_shorts_.get() + n_short_.get());
  job_arcs_.set(job_arcs_.get() + arcs);
}

void EdmJob::select_condition(int e) noexcept {
  condition_ = e > 0 ? tables_->condition(e) : nullptr;
  gen_arm_.set(condition_ != nullptr);
  if (condition_ == nullptr) return;
  on_time_us_.set(condition_->on_time_us);
  off_time_us_.set(condition_->off_time_us);
  servo_ref_v_.set(condition_->servo_ref_v);
  c_wear_ratio_.set(condition_->wear_ratio);
  c_tdr_.set(condition_->tdr_us);
}

bool EdmJob::in_position() const noexcept {
  return px_inpos_->get() && py_inpos_->get() && pz_inpos_->get();
}

void EdmJob::hold_position() noexcept {
  c_xref_.set(hold_x_);
  c_yref_.set(hold_y_);
  c_zref_.set(hold_z_);
  c_vffx_.set(0.0);
  c_vffy_.set(0.0);
  c_vffz_.set(0.0);
}

bool EdmJob::run_block(const MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                       rt::BlockStatus& status) noexcept {
  const double x = x_mm_.get(), y = y_mm_.get(), z = z_mm_.get();
  switch (b.kind) {
    case MotionKind::kCondition: {
      const machining::Condition* next =
          b.condition > 0 ? tables_->condition(b.condition) : nullptr;
      const bool positive = next != nullptr && next->polarity == machining::Polarity::kPositive;
      if (step_ == Step::kEnter && next != nullptr && positive != polarity_positive_value_) {
        gen_on_.set(false);
        wait_until_ = ctx.release + params_.polarity_settle;
        polarity_positive_value_ = positive;
        polarity_positive_.set(positive);
        step_ = Step::kSettle;
        return false;
      }
      if (step_ == Step::kSettle && ctx.release < wait_until_) return false;
      select_condition(b.condition);
      return true;
    }
    case MotionKind::kRotation:
      rotation_on_.set(b.on);
      return true;
    case MotionKind::kFlushing:
      flushing_on_.set(b.on);
      return true;
    case MotionKind::kDwell:
      if (step_ == Step::kEnter) {
        wait_until_ = ctx.release + rt::Duration(static_cast<std::int64_t>(b.dwell_s * 1e9));
        step_ = Step::kBusy;
      }
      return !hold && ctx.release >= wait_until_;
    case MotionKind::kRapid:
    case MotionKind::kLinear: {
      if (step_ == Step::kEnter) {  // sync the interpolator to the actual position
        c_lin_load_.set(true);
        status = rt::worst(status, lin_.update(ctx));
        step_ = Step::kLoad;
        hold_position();
        return false;
      }
      if (step_ == Step::kLoad) {
        c_lin_load_.set(false);
        c_lx_.set(b.target.x - x);
        c_ly_.set(b.target.y - y);
        c_lz_.set(b.target.z - z);
        const double f = b.kind == MotionKind::kRapid
                             ? params_.rapid_speed_mm_s
                             : (b.feed_mm_s > 0.0 ? b.feed_mm_s : params_.feed_default_mm_s);
        c_lin_feed_.set(f * 60.0);
        c_lin_start_.set(true);
        step_ = Step::kBusy;
      } else {
        c_lin_start_.set(false);
      }
      c_lin_hold_.set(hold);
      status = rt::worst(status, lin_.update(ctx));
      c_xref_.set(lin_rx_->get());
      c_yref_.set(lin_ry_->get());
      c_zref_.set(lin_rz_->get());
      c_vffx_.set(lin_vx_->get());
      c_vffy_.set(lin_vy_->get());
      c_vffz_.set(lin_vz_->get());
      hold_x_ = lin_rx_->get();
      hold_y_ = lin_ry_->get();
      hold_z_ = lin_rz_->get();
      return step_ == Step::kBusy && lin_done_->get() && !c_lin_start_.get() && in_position();
    }
    case MotionKind::kArcCw:
    case MotionKind::kArcCcw: {
      if (step_ == Step::kEnter) {
        c_arc_load_.set(true);
        status = rt::worst(status, arc_.update(ctx));
        step_ = Step::kLoad;
        hold_position();
        return false;
      }
      if (step_ == Step::kLoad) {
        c_arc_load_.set(false);
        c_arc_cw_.set(b.kind == MotionKind::kArcCw);
        c_i_.set(b.centre.x - x);
        c_j_.set(b.centre.y - y);
        c_ex_.set(b.target.x - x);
        c_ey_.set(b.target.y - y);
        const bool full = b.target.x == x && b.target.y == y;
        c_arc_full_.set(full && b.turns > 0);
        c_turns_.set(1 + b.turns);
        c_arc_feed_.set((b.feed_mm_s > 0.0 ? b.feed_mm_s : params_.feed_default_mm_s) * 60.0);
        c_arc_start_.set(true);
        step_ = Step::kBusy;
      } else {
        c_arc_start_.set(false);
      }
      c_arc_hold_.set(hold);
      status = rt::worst(status, arc_.update(ctx));
      c_xref_.set(arc_rx_->get());
      c_yref_.set(arc_ry_->get());
      c_zref_.set(hold_z_);
      c_vffx_.set(arc_vx_->get());
      c_vffy_.set(arc_vy_->get());
      c_vffz_.set(0.0);
      hold_x_ = arc_rx_->get();
      hold_y_ = arc_ry_->get();
      return step_ == Step::kBusy && arc_done_->get() && !c_arc_start_.get() && in_position();
    }
    case MotionKind::kDrill: {
      if (drill_returning_) return run_block(drill_return_, ctx, hold, status);
      hold_position();
      if (step_ == Step::kEnter) {
        drill_return_ = MotionBlock{};
        drill_return_.kind = MotionKind::kRapid;
        drill_return_.line = b.line;
        drill_return_.col = b.col;
        drill_return_.target = {x, y, z};
        wear_before_block_ = job_wear_mm_.get();
        c_depth_.set(-b.target.z);
        c_through_.set(false);
        c_drill_start_.set(true);
        step_ = Step::kBusy;
        return false;
      }
      c_drill_start_.set(false);
      c_hold_.set(hold);
      job_depth_mm_.set(std::max(job_depth_mm_.get(), drill_depth_->get()));
      job_wear_mm_.set(wear_before_block_ + drill_wear_->get());
      const bool done =
          drill_state_->get() == static_cast<std::int64_t>(DeepHoleDrill::State::kDone);
      if (done) {  // retracted out of the hole: back to where the block began, as a rapid
        hold_z_ = z;
        drill_returning_ = true;
        step_ = Step::kEnter;
      }
      return false;
    }
    case MotionKind::kOrbitFinish: {
      hold_position();
      if (step_ == Step::kEnter) {
        c_final_offset_.set(b.final_radius_mm - params_.orbit_radius_offset_mm);
        c_start_offset_.set(std::min(0.01, b.final_radius_mm - params_.orbit_radius_offset_mm));
        c_finish_start_.set(true);
        step_ = Step::kBusy;
        return false;
      }
      c_finish_start_.set(false);
      c_hold_.set(hold);
      const bool done = finish_state_->get() == static_cast<std::int64_t>(WallFinish::State::kDone);
      if (done) {
        hold_x_ = x;
        hold_y_ = y;
        polarity_positive_value_ = finish_pos_->get();
      }
      return done;
    }
    case MotionKind::kEnd:
      return true;
  }
  return true;
}

rt::BlockStatus EdmJob::update(const rt::CycleContext& ctx) noexcept {
  rt::BlockStatus status = rt::BlockStatus::kOk;
  const double x = x_mm_.get(), y = y_mm_.get(), z = z_mm_.get();
  c_td_sum_ns_.set(td_sum_ns_.get());
  c_td_count_.set(td_count_.get());
  c_n_open_.set(n_open_.get());
  c_n_short_.set(n_short_.get());
  c_x_.set(x);
  c_y_.set(y);
  c_z_.set(z);

  // Soft limits of the actual position (the program was checked at commit; this catches drift,
  // jogs and wrong offsets).
  bool outside = false;
  for (const machining::AxisLimits& a : tables_->axes) {
    const double v = a.name == 'X' ? x : (a.name == 'Y' ? y : z);
    if (v < a.min_mm - 1e-9 || v > a.max_mm + 1e-9) outside = true;
  }
  if (outside && !limit_alarm_raised_) {
    machine_->raise({rt::AlarmCode::kSoftLimit, rt::AlarmSeverity::kFault, ctx.release, name_,
                     "soft limit: an axis is outside its configured range", 0.0});
    limit_alarm_raised_ = true;
  } else if (!outside) {
    limit_alarm_raised_ = false;
  }

  const rt::MachineState ms = ctx.state;
  if (rt::is_safe_state(ms)) hold_valid_ = false;  // loops off: follow the axes
  if (state_value_ == State::kIdle) {
    // Between jobs the loops hold where the last move ended (so its overshoot settles back),
    // or, after power-on or a safe state, where the axes are.
    if (!hold_valid_) {
      hold_x_ = x;
      hold_y_ = y;
      hold_z_ = z;
      hold_valid_ = !rt::is_safe_state(ms);
    }
    if (ms == rt::MachineState::kRunning && job_->rt_begin()) {
      state_value_ = State::kRun;
      state_.set(1);
      begin_job_figures(ctx);
      step_ = Step::kEnter;
      condition_ = nullptr;
      gen_arm_.set(false);
    }
  } else if (ms != rt::MachineState::kRunning && ms != rt::MachineState::kHold) {
    finish_job(rt::JobOutcome::kAborted);  // stop, fault or E-stop
  }

  c_loop_enable_.set(!rt::is_safe_state(ms));
  bool block_done = false;
  if (state_value_ == State::kRun) {
    count_job_figures(ctx);
    const MotionBlock* b = job_->rt_current();
    if (b == nullptr || b->kind == MotionKind::kEnd) {
      finish_job(rt::JobOutcome::kFinished);
      machine_->command(rt::MachineCommand::kStop, ctx.release);
    } else {
      const bool hold = ms == rt::MachineState::kHold;
      // A new block waits while the machine holds; a started drill/finish block runs on.
      if (!(hold && step_ == Step::kEnter)) {
        block_done = run_block(*b, ctx, hold, status);
      } else {
        hold_position();
      }
      block_index_.set(static_cast<std::int64_t>(job_->progress().block_index));
      line_.set(b->line);
      if (block_done) {
        job_->rt_advance();
        step_ = Step::kEnter;
        drill_returning_ = false;
      }
    }
  } else {
    hold_position();
  }

  // The children that run every cycle (they idle when not started).
  status = rt::worst(status, drill_.update(ctx));
  status = rt::worst(status, finish_.update(ctx));
  status = rt::worst(status, px_.update(ctx));
  status = rt::worst(status, py_.update(ctx));
  status = rt::worst(status, pz_.update(ctx));
  if (px_ferr_->get() || py_ferr_->get() || pz_ferr_->get()) {
    machine_->raise({rt::AlarmCode::kFollowingError, rt::AlarmSeverity::kFault, ctx.release, name_,
                     "following error: an axis lags its reference beyond f_err_max_mm", 0.0});
  }

  // Outputs: who drives which axis.
  const std::int64_t ds = drill_state_->get();
  const bool drilling = ds != static_cast<std::int64_t>(DeepHoleDrill::State::kIdle) &&
                        ds != static_cast<std::int64_t>(DeepHoleDrill::State::kDone);
  const std::int64_t fs = finish_state_->get();
  const bool finishing = fs != static_cast<std::int64_t>(WallFinish::State::kIdle) &&
                         fs != static_cast<std::int64_t>(WallFinish::State::kDone);
  vx_.set(finishing ? finish_vx_->get() : px_v_->get());
  vy_.set(finishing ? finish_vy_->get() : py_v_->get());
  vz_.set(drilling ? drill_vz_->get() : pz_v_->get());
  if (drilling) hold_z_ = z;
  gen_on_.set(gen_arm_.get() && (drill_gen_->get() || finish_gen_->get()));
  polarity_positive_.set(finishing ? finish_pos_->get() : polarity_positive_value_);
  return status;
}

}  // namespace edm::programs
