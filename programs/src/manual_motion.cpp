#include "edm/programs/manual_motion.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/param_ranges.hpp"
#include "edm/machining/machine_tables.hpp"
#include "edm/runtime/machine.hpp"

namespace edm::programs {
namespace {

using rt::ManualError;
using rt::ManualMode;
using rt::ManualOp;
using rt::TouchTarget;

constexpr char kAxisName[3] = {'X', 'Y', 'Z'};
// A reference within this of its target has arrived (the encoder resolves far coarser).
constexpr double kArrived = 1e-7;
// In position (manual_motion_steps.cpp): at most this long after the reference arrived.
constexpr rt::Duration kSettleLimit = std::chrono::milliseconds(500);

int axis_of(char c) noexcept { return c == 'X' ? 0 : c == 'Y' ? 1 : c == 'Z' ? 2 : -1; }

}  // namespace

void ManualMotionParams::visit(rt::ParamVisitor& v) {
  namespace r = blocks::ranges;  // the shared physical ranges (param_ranges.hpp)
  v.param("jog_v_max_mm_s", jog_v_max_mm_s, {"mm/s", "fastest continuous jog", r::kSpeedMmS});
  v.param("accel_mm_s2", accel_mm_s2, {"mm/s2", "acceleration of manual moves", r::kAccelMmS2});
  v.param("kp_per_s", kp_per_s,
          {"1/s", "position gain that keeps the axis on its manual reference", r::kLoopGainPerS});
  // A dead-man time up to 1 min: longer is no dead-man.
  v.param("deadman", deadman,
          {"s", "a continuous jog not refreshed for this long stops (dead-man)",
           rt::open_closed(0.0, 60.0)});
  v.param("home_order", home_order,
          rt::load_time(
              {"", "the order in which the axes are referenced (X, Y, Z each at most once)"}));
  v.param("home_search_mm_s", home_search_mm_s,
          {"mm/s", "speed toward the reference switch", r::kSpeedMmS});
  v.param("home_latch_mm_s", home_latch_mm_s,
          {"mm/s", "slow speed onto the switch where the position is set", r::kSpeedMmS});
  v.param("home_back_off_mm", home_back_off_mm,
          {"mm", "back-off from the switch before the slow latch", r::kPositiveLengthMm});
  v.param("home_search_max_mm", home_search_max_mm,
          {"mm", "longest search for the switch (else the homing fails)", r::kPositiveLengthMm});
  v.param("home_x_mm", home_x_mm, {"mm", "machine X of the X reference switch", r::kPositionMm});
  v.param("home_y_mm", home_y_mm, {"mm", "machine Y of the Y reference switch", r::kPositionMm});
  v.param("home_z_mm", home_z_mm, {"mm", "machine Z of the Z reference switch", r::kPositionMm});
  v.param("touch_fast_mm_s", touch_fast_mm_s,
          {"mm/s", "first approach toward the work in touch mode", r::kSpeedMmS});
  v.param("touch_slow_mm_s", touch_slow_mm_s,
          {"mm/s", "second approach: the touch is where it makes contact", r::kSpeedMmS});
  v.param("touch_max_mm", touch_max_mm,
          {"mm", "longest approach without contact (else no contact)", r::kPositiveLengthMm});
  v.param("touch_back_off_mm", touch_back_off_mm,
          {"mm", "back-off after each contact", r::kPositiveLengthMm});
  // An electrode diameter up to 1 m.
  v.param("electrode_d_mm", electrode_d_mm,
          {"mm", "electrode diameter: an edge lies one radius beyond the axis at contact",
           rt::closed(0.0, 1000.0)});
  v.param("reference_required", reference_required,
          rt::load_time({"", "programs are refused until every axis is referenced"}));
  v.param("referenced_at_start", referenced_at_start,
          rt::load_time({"", "absolute encoders: every axis counts as referenced at power-on"}));
}

std::vector<rt::ParamError> ManualMotionParams::validate() const {
  std::vector<rt::ParamError> errs;
  bool seen[3] = {false, false, false};
  for (char c : home_order) {
    const int a = axis_of(c);
    if (a < 0 || seen[a]) {
      errs.push_back(
          {"home_order", "must list X, Y and Z, each at most once (got '" + home_order + "')"});
      break;
    }
    seen[a] = true;
  }
  if (touch_slow_mm_s > touch_fast_mm_s) {
    errs.push_back({"touch_slow_mm_s", "must not exceed touch_fast_mm_s"});
  }
  if (home_latch_mm_s > home_search_mm_s) {
    errs.push_back({"home_latch_mm_s", "must not exceed home_search_mm_s"});
  }
  return errs;
}

std::vector<rt::ParamError> ManualMotion::configure(const rt::BlockSetup& setup) {
  manual_ = setup.manual;
  tables_ = setup.tables;
  dt_s_ = rt::to_seconds(setup.period);
  if (manual_ == nullptr) return {{"", "ManualMotion needs the runtime's manual control"}};
  return {};
}

void ManualMotion::bind() {
  // After the YAML wiring: what is wired says what this machine can do.
  rt::ManualInfo info;
  info.available = true;
  info.home = any_switch_wired();
  info.touch = contact.connected();
  info.reference_required = params_.reference_required;
  info.deadman_ms = rt::to_seconds(params_.deadman) * 1e3;
  info.jog_v_max_mm_s = params_.jog_v_max_mm_s;
  info.electrode_d_mm = params_.electrode_d_mm;
  manual_->attach(info, params_.referenced_at_start ? 0x7 : 0x0);
}

void ManualMotion::activate() noexcept {
  step_ = Step::kIdle;
  job_op_ = false;
  job_ok_ = false;
  status_ = {};
  stop_outputs();
  mode.set(0);
  for (rt::Output<bool>& set : pos_set) set.set(false);
  if (manual_ != nullptr) {
    // Requests made before the first cycle are old news.
    rt::ManualRequest r;
    while (manual_->rt_poll(r, last_seq_)) {
    }
    status_.seen_seq = last_seq_;
    referenced.set(manual_->referenced());
    manual_->rt_publish(status_);
  }
}

void ManualMotion::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  if (step_ != Step::kIdle) end_operation(false, ManualError::kInterrupted, 0.0);
  job_op_ = false;
  job_ok_ = false;
  stop_outputs();
  mode.set(0);
  if (manual_ != nullptr) manual_->rt_publish(status_);
}

void ManualMotion::stop_outputs() noexcept {
  active.set(false);
  touch_mode.set(false);
  for (rt::Output<double>& v : v_cmd) v.set(0.0);
}

void ManualMotion::end_operation(bool ok, ManualError e, double t_s) noexcept {
  step_ = Step::kIdle;
  status_.result.seq = req_.seq;
  status_.result.op = req_.op;
  status_.result.target = req_.target;
  status_.result.ok = ok;
  status_.result.error = e;
  status_.result.t_s = t_s;
  status_.busy = false;
  status_.op = ManualOp::kNone;
  status_.mode = ManualMode::kIdle;
}

double ManualMotion::axis_mm(int axis) const noexcept {
  return pos[static_cast<std::size_t>(axis)].get();
}

bool ManualMotion::switch_on(int axis) const noexcept {
  return ref[static_cast<std::size_t>(axis)].get();
}

bool ManualMotion::any_switch_wired() const noexcept {
  return ref.x().connected() || ref.y().connected() || ref.z().connected();
}

bool ManualMotion::is_referenced(int axis) const noexcept {
  return (manual_->referenced() >> axis & 1U) != 0;
}

bool ManualMotion::limits(int axis, double& lo, double& hi) const noexcept {
  const machining::AxisLimits* l = tables_ != nullptr ? tables_->axis(kAxisName[axis]) : nullptr;
  if (l == nullptr || !is_referenced(axis)) return false;
  lo = l->min_mm;
  hi = l->max_mm;
  return true;
}

void ManualMotion::begin_move(int axis, double target, double speed) noexcept {
  if (axis != axis_) {  // a new axis: the old one holds where its reference stopped
    hold_[axis_] = prof_.pos;
    prof_.pos = hold_[axis];
    prof_.vel = 0.0;
    axis_ = axis;
  }
  prof_.target = target;
  prof_.speed = speed;
  prof_.done = false;
  travel_from_ = prof_.pos;
}

void ManualMotion::stop_now() noexcept {
  prof_.pos = axis_mm(axis_);
  prof_.vel = 0.0;
  prof_.target = prof_.pos;
  prof_.done = true;
}

void ManualMotion::step_profile(double dt) noexcept {
  if (prof_.done) return;
  const double a = params_.accel_mm_s2;
  const double d = prof_.target - prof_.pos;
  // The fastest speed from which the reference still stops at the target.
  const double v_stop = std::sqrt(2.0 * a * std::abs(d));
  const double v_des = std::copysign(std::min(prof_.speed, v_stop), d);
  prof_.vel += std::clamp(v_des - prof_.vel, -a * dt, a * dt);
  double next = prof_.pos + prof_.vel * dt;
  if ((d > 0.0 && next >= prof_.target) || (d < 0.0 && next <= prof_.target) ||
      std::abs(d) < kArrived) {
    next = prof_.target;
    prof_.vel = 0.0;
    prof_.done = true;
  }
  prof_.pos = next;
}

void ManualMotion::command_axes() noexcept {
  const double kp = params_.kp_per_s;
  for (int k = 0; k < 3; ++k) {
    const double target = k == axis_ ? prof_.pos : hold_[k];
    const double ff = k == axis_ ? prof_.vel : 0.0;
    v_cmd[static_cast<std::size_t>(k)].set(ff + kp * (target - axis_mm(k)));
  }
}

void ManualMotion::finish(bool ok, ManualError e, const rt::CycleContext& ctx) noexcept {
  end_operation(ok, e, rt::to_seconds(ctx.release));
  stop_outputs();
}

void ManualMotion::finish_settled(bool ok, ManualError e, const rt::CycleContext& ctx) noexcept {
  pending_ok_ = ok;
  pending_error_ = e;
  settle_until_ = ctx.release + kSettleLimit;
  settle_cycles_ = 0;
  step_ = Step::kInPosition;
}

void ManualMotion::start(const rt::ManualRequest& r, const rt::CycleContext& ctx) noexcept {
  if (r.op == ManualOp::kStop) {
    if (step_ != Step::kIdle) finish(false, ManualError::kStopped, ctx);
    return;
  }
  if (step_ == Step::kJog && r.op == ManualOp::kJogVelocity && req_.op == ManualOp::kJogVelocity &&
      r.axis == req_.axis && r.value == req_.value) {
    refreshed_ = ctx.release;  // the same jog again: the dead-man is refreshed
    req_.seq = r.seq;
    return;
  }
  if (step_ != Step::kIdle) {
    // Another request while busy: only a continuous jog replaces a continuous jog (a new speed
    // or axis); anything else is refused, and says so (refused_seq). The bridge refuses it
    // first (hmi_bridge op_states.cpp: the same rule); this is the RT side's own guard.
    const bool replaces = r.op == ManualOp::kJogVelocity && req_.op == ManualOp::kJogVelocity &&
                          (step_ == Step::kJog || step_ == Step::kInPosition);
    if (!replaces) {
      status_.refused_seq = r.seq;
      return;
    }
  }
  const bool was_idle = step_ == Step::kIdle;
  req_ = r;
  status_.result = {};
  status_.result.seq = 0;
  if (was_idle) {
    for (int k = 0; k < 3; ++k) hold_[k] = axis_mm(k);
    axis_ = 0;
    prof_ = {};
    prof_.pos = hold_[0];
  }
  for (int k = 0; k < 3; ++k) start_[k] = k == axis_ ? prof_.pos : hold_[k];
  refreshed_ = ctx.release;
  switch (r.op) {
    case ManualOp::kJogDistance:
    case ManualOp::kJogVelocity: {
      const int a = r.axis;
      if (a < 0 || a > 2 || !std::isfinite(r.value)) {
        finish(false, ManualError::kBadRequest, ctx);
        return;
      }
      const double from = a == axis_ ? prof_.pos : hold_[a];
      double lo = 0.0, hi = 0.0;
      const bool limited = limits(a, lo, hi);
      if (r.op == ManualOp::kJogDistance) {
        const double d = std::abs(r.value);
        if (d < 0.001 - 1e-12 || d > 10.0 + 1e-12) {
          finish(false, ManualError::kBadRequest, ctx);
          return;
        }
        const double target = from + r.value;
        if (limited && (target < lo || target > hi)) {
          finish(false, ManualError::kSoftLimit, ctx);
          return;
        }
        begin_move(a, target, params_.jog_v_max_mm_s);
      } else {
        const double v = r.value;
        if (std::abs(v) > params_.jog_v_max_mm_s + 1e-12) {
          finish(false, ManualError::kBadRequest, ctx);
          return;
        }
        if (v == 0.0) {
          if (!was_idle) {
            begin_move(a, a == axis_ ? prof_.pos : hold_[a], params_.jog_v_max_mm_s);
            prof_.target =
                prof_.pos +
                std::copysign(prof_.vel * prof_.vel / (2.0 * params_.accel_mm_s2), prof_.vel);
          } else {
            finish(true, ManualError::kNone, ctx);
            return;
          }
        } else {
          const double far = v > 0.0 ? (limited ? hi : from + params_.home_search_max_mm)
                                     : (limited ? lo : from - params_.home_search_max_mm);
          begin_move(a, far, std::abs(v));
        }
      }
      step_ = Step::kJog;
      status_.mode = ManualMode::kJog;
      break;
    }
    case ManualOp::kHome:
      if (!any_switch_wired()) {
        finish(false, ManualError::kNotAvailable, ctx);
        return;
      }
      home_todo_ = r.axes & 0x7;
      home_next_ = 0;
      status_.mode = ManualMode::kHome;
      step_ = Step::kHomeSettle;  // next_home_axis() picks the first
      next_home_axis(ctx);
      break;
    case ManualOp::kTouch:
      if (!contact.connected()) {
        finish(false, ManualError::kNotAvailable, ctx);
        return;
      }
      touch_index_ = 0;
      status_.mode = ManualMode::kTouch;
      touch_mode.set(true);  // the sensing voltage first: contact reads only in touch mode
      settle_cycles_ = 0;
      step_ = Step::kTouchArm;
      break;
    case ManualOp::kNone:
    case ManualOp::kStop: return;
  }
  if (step_ != Step::kIdle) {
    status_.busy = true;
    status_.op = r.op;
    active.set(true);
  }
}

void ManualMotion::next_home_axis(const rt::CycleContext& ctx) noexcept {
  while (home_next_ < params_.home_order.size()) {
    const int a = axis_of(params_.home_order[home_next_++]);
    if (a < 0 || (home_todo_ >> a & 1U) == 0) continue;
    if (!ref[static_cast<std::size_t>(a)].connected()) {
      finish(false, ManualError::kNotAvailable, ctx);
      return;
    }
    begin_move(a, a == axis_ ? prof_.pos : hold_[a], params_.home_search_mm_s);
    prof_.done = true;
    step_ = Step::kHomeOff;
    return;
  }
  finish(true, ManualError::kNone, ctx);
  status_.result.x = pos.x().get();
  status_.result.y = pos.y().get();
  status_.result.z = pos.z().get();
}

rt::BlockStatus ManualMotion::update(const rt::CycleContext& ctx) noexcept {
  for (rt::Output<bool>& set : pos_set) set.set(false);
  if (manual_ == nullptr) return rt::BlockStatus::kOk;

  const bool ready = enable.get() || job_op_;
  if (!ready && step_ != Step::kIdle) finish(false, ManualError::kInterrupted, ctx);
  // Every request queued since the last cycle, in order: none is lost to a newer one.
  rt::ManualRequest r;
  while (manual_->rt_poll(r, last_seq_)) {
    status_.seen_seq = r.seq;
    if (r.op == ManualOp::kNone || (r.op == ManualOp::kStop && !ready)) continue;
    if (job_op_) {
      if (r.op == ManualOp::kStop) continue;
      // The job's touch owns the axes: the operator's request is answered, the touch runs on.
      status_.result = {};
      status_.result.seq = r.seq;
      status_.result.op = r.op;
      status_.result.target = r.target;
      status_.result.error = ManualError::kInterrupted;
      status_.result.t_s = rt::to_seconds(ctx.release);
    } else if (!ready) {  // a request made while not READY is answered at once
      req_ = r;
      finish(false, ManualError::kInterrupted, ctx);
    } else {
      start(r, ctx);
    }
  }
  if (!ready) {
    referenced.set(manual_->referenced());
    mode.set(0);
    manual_->rt_publish(status_);
    return rt::BlockStatus::kOk;
  }

  advance(ctx);
  if (step_ == Step::kHomeSettle) {  // the readings jump: no position correction now
    for (rt::Output<double>& v : v_cmd) v.set(0.0);
  } else if (step_ != Step::kIdle) {
    command_axes();
  }
  if (job_op_ && step_ == Step::kIdle) {  // the job's touch has ended
    job_op_ = false;
    job_ok_ = status_.result.ok;
    job_z_mm_ = status_.result.z;
  }
  mode.set(static_cast<std::int64_t>(status_.mode));
  referenced.set(manual_->referenced());
  manual_->rt_publish(status_);
  return rt::BlockStatus::kOk;
}

void ManualMotion::abort_job_touch() noexcept {
  if (!job_op_) return;
  end_operation(false, ManualError::kInterrupted, 0.0);
  stop_outputs();
  job_op_ = false;
  job_ok_ = false;
}

bool ManualMotion::begin_job_touch_z(const rt::CycleContext& ctx) noexcept {
  if (step_ != Step::kIdle || job_op_ || !contact.connected()) return false;
  rt::ManualRequest r;
  r.op = ManualOp::kTouch;
  r.target = TouchTarget::kZ;
  r.seq = 0;  // no operator's request: nothing in ManualControl waits for this result
  job_op_ = true;
  job_ok_ = false;
  start(r, ctx);
  return true;
}

}  // namespace edm::programs
