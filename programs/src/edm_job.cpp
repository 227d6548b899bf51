#include "edm/programs/edm_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/machine.hpp"

namespace edm::programs {
namespace {
using machining::MotionBlock;
using machining::MotionKind;

// The loops must be able to follow a rapid with margin for the feed-forward's overshoot.
constexpr double kLoopSpeedMargin = 1.5;
// An axis stands still below this speed; a move is complete once every axis has for this many
// cycles (and every loop is in its window).
constexpr double kStillSpeedMmS = 0.2;
constexpr std::int64_t kStillCycles = 5;
}  // namespace

void EdmJobParams::visit(rt::ParamVisitor& v) {
  namespace r = blocks::ranges;  // the shared physical ranges (param_ranges.hpp)
  v.param("rapid_speed_mm_s", rapid_speed_mm_s, {"mm/s", "speed of rapids", r::kSpeedMmS});
  v.param("feed_default_mm_s", feed_default_mm_s,
          {"mm/s", "feed of linear moves and arcs whose block has none", r::kSpeedMmS});
  // An electrode radius plus a side gap: up to 1 m (a die-sinking electrode of 2 m).
  v.param("orbit_radius_offset_mm", orbit_radius_offset_mm,
          {"mm", "orbit offset = final radius - this (electrode radius + finishing side gap)",
           rt::open_closed(0.0, 1000.0)});
  v.param("polarity_settle", polarity_settle,
          {"s", "generator-off wait when a condition changes the polarity", r::kSettleS});
}

EdmJob::EdmJob()
    : drill_(add_child<DeepHoleDrill>("drill")),
      finish_(add_child<WallFinish>("finish")),
      lin_(add_child<blocks::LinearInterpolator>("lin")),
      arc_(add_child<blocks::CircularInterpolator>("arc")),
      px_(add_child<blocks::PositionLoop>("px")),
      py_(add_child<blocks::PositionLoop>("py")),
      pz_(add_child<blocks::PositionLoop>("pz")),
      manual_(add_child<ManualMotion>("manual")),
      probe_(add_child<DepthProbe>("probe")),
      axes_(add_child<AxisArbiter>("axes")),
      wire_(add_child<WireCut>("wire")),
      cycles_{&drill_, &finish_} {}

std::vector<rt::ParamError> EdmJob::configure_self(const rt::BlockSetup& setup) {
  std::vector<rt::ParamError> errs;
  machine_ = setup.machine;
  manual_control_ = setup.manual;
  job_ = setup.job;
  if (job_ != nullptr) job_->attach_runner();
  tables_ = setup.tables;
  electrode_ = setup.electrode;  // none (a test rig): no length compensation
  if (machine_ == nullptr || job_ == nullptr || tables_ == nullptr) {
    errs.push_back({"", "EdmJob needs the runtime's machine, job store and tables"});
    return errs;
  }
  const double v_needed = kLoopSpeedMargin * params_.rapid_speed_mm_s;
  for (auto [loop, name] :
       {std::pair<blocks::PositionLoop*, const char*>{&px_, "px"}, {&py_, "py"}, {&pz_, "pz"}}) {
    if (loop->params().v_max_mm_s < v_needed) {
      errs.push_back({std::string(name) + ".v_max_mm_s",
                      "must be >= 1.5 x rapid_speed_mm_s (" + std::to_string(v_needed) +
                          " mm/s): the loop could not follow a rapid"});
    }
  }
  return errs;
}

void EdmJob::bind_self() {
  pulses.feed(drill_.pulses);
  pulses.feed(finish_.pulses);
  drill_.z_mm.follow(pos.z());
  for (std::size_t a = 0; a < rt::kAxes; ++a) manual_.pos[a].follow(pos[a]);
  finish_.x_mm.follow(pos.x());
  finish_.y_mm.follow(pos.y());
  px_.x_mm.follow(pos.x());
  py_.x_mm.follow(pos.y());
  pz_.x_mm.follow(pos.z());
  // The axes: manual motion and the loops by wire, the cycles' claims driven (command_axes()).
  axes_.manual.connect(manual_.active);
  for (std::size_t a = 0; a < rt::kAxes; ++a) axes_.manual_v[a].connect(manual_.v_cmd[a]);
  axes_.loop_v.x().connect(px_.v_cmd_mm_s);
  axes_.loop_v.y().connect(py_.v_cmd_mm_s);
  axes_.loop_v.z().connect(pz_.v_cmd_mm_s);
  // Everything else a child reads is driven by the sequence (Input::drive), as an IEC 61131-3
  // FB call passes its parameters: no output of this block exists only to feed a child.
  for (rt::Input<bool>* in :
       {&drill_.start, &drill_.hold, &finish_.start, &finish_.hold, &manual_.enable, &lin_.start,
        &lin_.hold, &lin_.load, &arc_.start, &arc_.hold, &arc_.load, &arc_.cw, &arc_.full_circle,
        &px_.enable, &py_.enable, &pz_.enable}) {
    in->claim();
  }
  for (std::size_t a = 0; a < rt::kAxes; ++a) {
    axes_.cycle[a].claim();
    axes_.cycle_v[a].claim();
    lin_.load_pos[a].claim();
    lin_.length[a].claim();
  }
  for (rt::Input<double>* in : {&drill_.depth_mm,
                                &drill_.depth_done_mm,
                                &drill_.resume_touch_z_mm,
                                &drill_.resume_wear_mm,
                                &drill_.contact_z_mm,
                                &drill_.contact_depth_mm,
                                &drill_.wear_ratio,
                                &drill_.area_ratio,
                                &drill_.tdr_us,
                                &finish_.final_offset_mm,
                                &finish_.start_offset_mm,
                                &finish_.feed_mm_min,
                                &lin_.feed_mm_min,
                                &arc_.load_x_mm,
                                &arc_.load_y_mm,
                                &arc_.i_mm,
                                &arc_.j_mm,
                                &arc_.ex_mm,
                                &arc_.ey_mm,
                                &arc_.feed_mm_min,
                                &px_.x_ref_mm,
                                &py_.x_ref_mm,
                                &pz_.x_ref_mm,
                                &px_.v_ff_mm_s,
                                &py_.v_ff_mm_s,
                                &pz_.v_ff_mm_s}) {
    in->claim();
  }
  for (rt::Input<double>* in :
       {&drill_.feed_override, &finish_.feed_override, &arc_.feed_override, &lin_.feed_override}) {
    in->claim(1.0);
  }
  arc_.turns.claim();
}

void EdmJob::activate_self() noexcept {
  state_value_ = State::kIdle;
  still_cycles_ = 0;
  last_x_ = pos.x().get();
  last_y_ = pos.y().get();
  last_z_ = pos.z().get();
  hold_valid_ = false;
  step_ = Step::kEnter;
  condition_ = nullptr;
  polarity_positive_value_ = false;
  stop_outputs();
  gen_arm.set(false);
  flushing_on.set(false);
  rotation_on.set(false);
  state.set(0);
  jobs_finished.set(0);
}

rt::BlockStatus EdmJob::command_axes(const rt::CycleContext& ctx) noexcept {
  AxisClaim claim;
  for (const MachiningCycle* c : cycles_) {
    if (!c->running()) continue;
    const AxisClaim c_axes = c->axes();
    for (std::size_t a = 0; a < rt::kAxes; ++a) {
      if (c_axes.claimed[a] && !claim.claimed[a]) {  // the first running cycle's claim wins
        claim.claimed[a] = true;
        claim.v_mm_s[a] = c_axes.v_mm_s[a];
      }
    }
  }
  for (std::size_t a = 0; a < rt::kAxes; ++a) {
    axes_.cycle[a].drive(claim.claimed[a]);
    axes_.cycle_v[a].drive(claim.v_mm_s[a]);
  }
  return step(axes_, ctx);
}

void EdmJob::set_hold(bool hold) noexcept {
  drill_.hold.drive(hold);
  finish_.hold.drive(hold);  // one hold for either cycle
}

void EdmJob::stop_outputs() noexcept {
  gen_on.set(false);
  drill_.start.drive(false);
  finish_.start.drive(false);
  lin_.start.drive(false);
  arc_.start.drive(false);
}

void EdmJob::safe_state_self(const rt::SafeStateRequest& /*request*/) noexcept {
  // The children back Z off (drill) and stop the orbit (finish); the job ends.
  gen_on.set(false);
  gen_arm.set(false);
  if (state_value_ == State::kRun) finish_job(rt::JobOutcome::kAborted);
}

void EdmJob::finish_job(rt::JobOutcome outcome) noexcept {
  if (job_ != nullptr) job_->rt_finish(outcome);
  if (outcome == rt::JobOutcome::kAborted) {
    // An operator stop is no safe state: the children must still end their cycles (a drill left
    // running would creep down dark, counting wear it never made).
    drill_.abort();
    finish_.abort();
    manual_.abort_job_touch();
  }
  drill_returning_ = false;
  cut_continuing_ = false;
  wire_.reset();
  probe_.stop();
  if (outcome == rt::JobOutcome::kFinished) jobs_finished.set(jobs_finished.get() + 1);
  state_value_ = State::kIdle;
  state.set(0);
  step_ = Step::kEnter;
  drill_.start.drive(false);
  set_hold(false);
  finish_.start.drive(false);
  gen_arm.set(false);
  gen_on.set(false);
}

double EdmJob::z_compensation(const MotionBlock& b) const noexcept {
  if (electrode_ == nullptr || b.electrode_ref_mm <= 0.0 || !electrode_->known()) return 0.0;
  return electrode_->length_mm() - b.electrode_ref_mm;
}

void EdmJob::wear_electrode() noexcept {
  if (electrode_ == nullptr || electrode_at_start_mm_ <= 0.0) return;
  // Never 0 (that is "unknown"): an electrode worn to nothing reads 1 µm.
  // A resumed hole's wear includes its interrupted job's, which that job already took off.
  const double worn = figures_.job_wear_mm.get() - resumed_wear_mm_;
  electrode_->set_length_mm(std::max(1e-3, electrode_at_start_mm_ - worn));
}

void EdmJob::select_condition(int e) noexcept {
  condition_ = e > 0 ? tables_->condition(e) : nullptr;
  gen_arm.set(condition_ != nullptr && !dry_run.get());  // a dry run never arms the generator
  if (condition_ == nullptr) return;
  on_time_us.set(condition_->on_time_us);
  off_time_us.set(condition_->off_time_us);
  servo_ref_v.set(condition_->servo_ref_v);
  drill_.wear_ratio.drive(condition_->wear_ratio);
  drill_.area_ratio.drive(condition_->area_ratio);
  drill_.tdr_us.drive(condition_->tdr_us);
}

bool EdmJob::in_position() const noexcept {
  return px_.in_position.get() && py_.in_position.get() && pz_.in_position.get() &&
         still_cycles_ >= kStillCycles;
}

void EdmJob::set_reference(double x, double y, double z, double vx, double vy, double vz) noexcept {
  px_.x_ref_mm.drive(x);
  py_.x_ref_mm.drive(y);
  pz_.x_ref_mm.drive(z);
  px_.v_ff_mm_s.drive(vx);
  py_.v_ff_mm_s.drive(vy);
  pz_.v_ff_mm_s.drive(vz);
}

void EdmJob::hold_position() noexcept { set_reference(hold_x_, hold_y_, hold_z_, 0.0, 0.0, 0.0); }

void EdmJob::set_move_from() noexcept {
  move_from_x_ = hold_valid_ ? hold_x_ : pos.x().get();
  move_from_y_ = hold_valid_ ? hold_y_ : pos.y().get();
  move_from_z_ = hold_valid_ ? hold_z_ : pos.z().get();
  lin_.load_pos.x().drive(move_from_x_);
  lin_.load_pos.y().drive(move_from_y_);
  lin_.load_pos.z().drive(move_from_z_);
  arc_.load_x_mm.drive(move_from_x_);
  arc_.load_y_mm.drive(move_from_y_);
}

bool EdmJob::run_linear(const MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                        rt::BlockStatus& status) noexcept {
  if (step_ == Step::kEnter) {  // sync the interpolator to where the move starts
    set_move_from();
    lin_.load.drive(true);
    status = rt::worst(status, step(lin_, ctx));
    step_ = Step::kLoad;
    hold_position();
    return false;
  }
  if (step_ == Step::kLoad) {
    lin_.load.drive(false);
    lin_.length.x().drive(b.target.x - move_from_x_);
    lin_.length.y().drive(b.target.y - move_from_y_);
    const double comp =
        b.kind == MotionKind::kRapid || b.kind == MotionKind::kLinear ? z_compensation(b) : 0.0;
    z_comp_mm.set(comp);
    lin_.length.z().drive(b.target.z + comp - move_from_z_);
    const double f = b.kind == MotionKind::kRapid
                         ? params_.rapid_speed_mm_s
                         : (b.feed_mm_s > 0.0 ? b.feed_mm_s : params_.feed_default_mm_s);
    lin_.feed_mm_min.drive(f * 60.0);
    lin_.start.drive(true);
    step_ = Step::kBusy;
  } else {
    lin_.start.drive(false);
  }
  lin_.hold.drive(hold);
  // Rapids are never sped beyond their programmed speed (the loops' margin is sized for it).
  lin_.feed_override.drive(b.kind == MotionKind::kRapid ? std::min(feed_override_, 1.0)
                                                        : feed_override_);
  status = rt::worst(status, step(lin_, ctx));
  set_reference(lin_.ref_pos.x().get(), lin_.ref_pos.y().get(), lin_.ref_pos.z().get(),
                lin_.vel.x().get(), lin_.vel.y().get(), lin_.vel.z().get());
  hold_x_ = lin_.ref_pos.x().get();
  hold_y_ = lin_.ref_pos.y().get();
  hold_z_ = lin_.ref_pos.z().get();
  return step_ == Step::kBusy && lin_.done.get() && !lin_.start.driven() && in_position();
}

bool EdmJob::run_arc(const MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                     rt::BlockStatus& status) noexcept {
  if (step_ == Step::kEnter) {
    set_move_from();
    arc_.load.drive(true);
    status = rt::worst(status, step(arc_, ctx));
    step_ = Step::kLoad;
    hold_position();
    return false;
  }
  if (step_ == Step::kLoad) {
    const double x = move_from_x_, y = move_from_y_;
    arc_.load.drive(false);
    arc_.cw.drive(b.kind == MotionKind::kArcCw);
    arc_.i_mm.drive(b.centre.x - x);
    arc_.j_mm.drive(b.centre.y - y);
    arc_.ex_mm.drive(b.target.x - x);
    arc_.ey_mm.drive(b.target.y - y);
    const bool full = b.target.x == x && b.target.y == y;
    arc_.full_circle.drive(full && b.turns > 0);
    arc_.turns.drive(1 + b.turns);
    arc_.feed_mm_min.drive((b.feed_mm_s > 0.0 ? b.feed_mm_s : params_.feed_default_mm_s) * 60.0);
    arc_.start.drive(true);
    step_ = Step::kBusy;
  } else {
    arc_.start.drive(false);
  }
  arc_.hold.drive(hold);
  status = rt::worst(status, step(arc_, ctx));
  set_reference(arc_.rx_mm.get(), arc_.ry_mm.get(), hold_z_, arc_.vx_mm_s.get(), arc_.vy_mm_s.get(),
                0.0);
  hold_x_ = arc_.rx_mm.get();
  hold_y_ = arc_.ry_mm.get();
  return step_ == Step::kBusy && arc_.done.get() && !arc_.start.driven() && in_position();
}

bool EdmJob::run_finish(const MotionBlock& b, bool hold) noexcept {
  hold_position();
  if (step_ == Step::kEnter) {
    finish_.final_offset_mm.drive(b.final_radius_mm - params_.orbit_radius_offset_mm);
    finish_.start_offset_mm.drive(
        std::min(0.01, b.final_radius_mm - params_.orbit_radius_offset_mm));
    finish_.feed_mm_min.drive(b.feed_mm_s > 0.0 ? b.feed_mm_s * 60.0
                                                : 0.0);  // G160's F (0: default)
    finish_.start.drive(true);
    step_ = Step::kBusy;
    return false;
  }
  finish_.start.drive(false);
  set_hold(hold);
  const bool done = finish_.state.get() == static_cast<std::int64_t>(WallFinish::State::kDone);
  if (done) {
    hold_x_ = pos.x().get();
    hold_y_ = pos.y().get();
    polarity_positive_value_ = finish_.polarity_positive.get();
  }
  return done;
}

bool EdmJob::run_block(const MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                       rt::BlockStatus& status) noexcept {
  if (step_ == Step::kEnter && !b.cut) {  // another kind of block ends a cut's history
    cut_continuing_ = false;
    wire_.reset();
  }
  switch (b.kind) {
    case MotionKind::kCondition: {
      const machining::Condition* next =
          b.condition > 0 ? tables_->condition(b.condition) : nullptr;
      const bool positive = next != nullptr && next->polarity == machining::Polarity::kPositive;
      if (step_ == Step::kEnter && next != nullptr && positive != polarity_positive_value_) {
        gen_on.set(false);
        wait_until_ = ctx.release + params_.polarity_settle;
        polarity_positive_value_ = positive;
        polarity_positive.set(positive);
        step_ = Step::kSettle;
        return false;
      }
      if (step_ == Step::kSettle && ctx.release < wait_until_) return false;
      select_condition(b.condition);
      return true;
    }
    case MotionKind::kRotation: rotation_on.set(b.on); return true;
    case MotionKind::kFlushing: flushing_on.set(b.on); return true;
    case MotionKind::kDwell:
      if (step_ == Step::kEnter) {
        wait_until_ = ctx.release + rt::Duration(static_cast<std::int64_t>(b.dwell_s * 1e9));
        step_ = Step::kBusy;
      }
      return !hold && ctx.release >= wait_until_;
    case MotionKind::kRapid:
    case MotionKind::kLinear:
      if (b.cut && !dry_run.get()) return run_cut(b, ctx, hold);  // a dry run moves at F
      return run_linear(b, ctx, hold, status);
    case MotionKind::kArcCw:
    case MotionKind::kArcCcw:
      if (b.cut && !dry_run.get()) return run_cut(b, ctx, hold);
      return run_arc(b, ctx, hold, status);
    case MotionKind::kProgramStop: return b.on || run_program_stop(ctx);  // M01: no switch yet
    case MotionKind::kDrill:
      return dry_run.get() || run_drill(b, ctx, hold, status);  // a dry run skips it
    case MotionKind::kOrbitFinish: return dry_run.get() || run_finish(b, hold);
    case MotionKind::kEnd: return true;
  }
  return true;
}

rt::BlockStatus EdmJob::update_self(const rt::CycleContext& ctx) noexcept {
  rt::BlockStatus status = rt::BlockStatus::kOk;
  cutting_ = false;
  // The operator's feed override, read once a cycle for every child that moves.
  feed_override_ = machine_ != nullptr ? machine_->feed_override() : 1.0;
  for (rt::Input<double>* in :
       {&drill_.feed_override, &finish_.feed_override, &arc_.feed_override}) {
    in->drive(feed_override_);
  }
  const double x = pos.x().get(), y = pos.y().get(), z = pos.z().get();
  const double still_mm = kStillSpeedMmS * ctx.dt_s;
  const bool still = std::abs(x - last_x_) <= still_mm && std::abs(y - last_y_) <= still_mm &&
                     std::abs(z - last_z_) <= still_mm;
  still_cycles_ = still ? still_cycles_ + 1 : 0;
  last_x_ = x;
  last_y_ = y;
  last_z_ = z;

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
    const bool may_run = manual_control_ == nullptr || manual_control_->may_run_programs();
    if (ms == rt::MachineState::kRunning && (!may_run || manual_.active.get())) {
      // Not referenced (or still moving by hand): no job; back to READY (the bridge refuses
      // such a start first, this is the runtime's own guard).
      machine_->command(rt::MachineCommand::kStop, ctx.release);
    } else if (ms == rt::MachineState::kRunning && (drill_.running() || finish_.running())) {
      // The last job was stopped and its cycle still retracts (out of the hole, off the wall):
      // the machine shows READY from the stop on, so a start may come now; the new job begins
      // once the retract has ended, never with two commanders of one axis.
    } else if (ms == rt::MachineState::kRunning && job_->rt_begin()) {
      dry_run.set(job_->current_options().dry_run);
      state_value_ = State::kRun;
      state.set(1);
      figures_.begin(ctx.release);
      // A dry run never sparks: it wears nothing.
      electrode_at_start_mm_ =
          electrode_ != nullptr && !job_->current_options().dry_run ? electrode_->length_mm() : 0.0;
      resumed_wear_mm_ = 0.0;
      step_ = Step::kEnter;
      condition_ = nullptr;
      gen_arm.set(false);
    }
  } else if (ms != rt::MachineState::kRunning && ms != rt::MachineState::kHold) {
    finish_job(rt::JobOutcome::kAborted);  // stop, fault or E-stop
  }

  for (blocks::PositionLoop* loop : {&px_, &py_, &pz_}) loop->enable.drive(!rt::is_safe_state(ms));
  if (state_value_ == State::kRun) {
    figures_.count(ctx.release, {pulses.n_open.get(), n_normal.get(), n_transient_arc.get(),
                                 n_stable_arc.get(), pulses.n_short.get()});
    const MotionBlock* b = job_->rt_current();
    if (b == nullptr || b->kind == MotionKind::kEnd) {
      finish_job(rt::JobOutcome::kFinished);
      machine_->command(rt::MachineCommand::kStop, ctx.release);
    } else {
      const bool hold = ms == rt::MachineState::kHold;
      bool block_done = false;
      // A new block waits while the machine holds; a started drill/finish block runs on.
      if (!(hold && step_ == Step::kEnter)) {
        block_done = run_block(*b, ctx, hold, status);
      } else {
        hold_position();
      }
      block_index.set(static_cast<std::int64_t>(job_->progress().block_index));
      line.set(b->line);
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
  manual_.enable.drive(ms == rt::MachineState::kReady && state_value_ == State::kIdle);
  status = rt::worst(status, step(manual_, ctx));
  const bool manual = manual_.active.get();
  if (manual) hold_valid_ = false;  // after it the loops hold where the axes are
  status = rt::worst(status, step(drill_, ctx));
  status = rt::worst(status, step(finish_, ctx));
  status = rt::worst(status, step(px_, ctx));
  status = rt::worst(status, step(py_, ctx));
  status = rt::worst(status, step(pz_, ctx));

  status = rt::worst(status, command_axes(ctx));
  if (state_value_ == State::kRun) wear_electrode();
  electrode_mm.set(electrode_ != nullptr ? electrode_->length_mm() : 0.0);
  if (drill_.running()) hold_z_ = z;
  bool generator = false;
  for (const MachiningCycle* c : cycles_) generator = generator || c->generator_on();
  generator = generator || cutting_;
  gen_on.set(gen_arm.get() && generator);
  polarity_positive.set(finish_.running() ? finish_.polarity_positive.get()
                                          : polarity_positive_value_);
  return status;
}

}  // namespace edm::programs
