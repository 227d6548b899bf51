#include "edm/runtime/supervisor.hpp"

#include <algorithm>
#include <cmath>

namespace edm::rt {

namespace {

// Below this, two positions or speeds are the same (the encoder resolves 1 µm).
constexpr double kEpsilon = 1e-9;

// A per-cycle pulse counter above this is a broken signal (no generator fires 2^40 pulses in a
// cycle), and the sum of a few stays far from int64 overflow.
constexpr std::int64_t kMaxPulseCount = std::int64_t{1} << 40;

/// The highest speed from which an axis decelerating at a_max after one more cycle at that
/// speed stops within d: v·dt + v²/(2a) = d.
double stop_speed(double d_mm, double a_mm_s2, double dt_s) noexcept {
  if (d_mm <= 0.0) {
    return 0.0;
  }
  return a_mm_s2 * (std::sqrt(dt_s * dt_s + 2.0 * d_mm / a_mm_s2) - dt_s);
}

Alarm make_alarm(AlarmCode code, AlarmSeverity sev, TimePoint now, const char* source,
                 const char* text, double value) noexcept {
  return Alarm{code, sev, now, source, text, value};
}

}  // namespace

Supervisor::Supervisor(Machine& machine, SupervisorSetup setup, Duration period)
    : machine_(machine),
      axes_(setup.axes.size()),
      command_(setup.axes.size(), 0.0),
      electrode_mm_(setup.electrode_mm),
      electrode_margin_mm_(setup.electrode_margin_mm),
      wire_broken_(setup.wire_broken),
      generator_(std::move(setup.generator)),
      manual_(setup.manual),
      short_count_(setup.short_count),
      pulse_counts_(std::move(setup.pulse_counts)),
      short_limit_(setup.short_limit),
      period_(period),
      dt_s_(to_seconds(period)) {
  for (std::size_t k = 0; k < axes_.size(); ++k) {
    axes_[k].cfg = setup.axes[k];
    const char n = setup.axes[k].limits.name;
    axes_[k].ref_bit = n == 'X' ? 0 : n == 'Y' ? 1 : n == 'Z' ? 2 : -1;
    axes_[k].source = std::string("safety.") + setup.axes[k].limits.name;
    axes_[k].speed_source = axes_[k].source + ".v_max";
  }
}

void Supervisor::condition(bool active, bool& raised, const Alarm& alarm) noexcept {
  if (active) {
    machine_.raise(alarm);  // a repeat only counts: one alarm per occurrence
    raised = true;
  } else if (raised) {
    machine_.clear_alarm(alarm.code, alarm.source);
    raised = false;
  }
}

void Supervisor::check_machine(TimePoint now) noexcept {
  if (electrode_mm_ != nullptr) {
    const double left = electrode_mm_->get();
    condition(
        !(left > electrode_margin_mm_), electrode_raised_,
        make_alarm(AlarmCode::kElectrodeUsedUp, AlarmSeverity::kFault, now, "safety.electrode",
                   "electrode used up: its length left is at the margin", left));
  }
  if (wire_broken_ != nullptr) {
    condition(wire_broken_->get(), wire_raised_,
              make_alarm(AlarmCode::kWireBreak, AlarmSeverity::kFault, now, "safety.wire",
                         "wire break", 1.0));
  }
}

bool Supervisor::cycle_reads_short() const noexcept {
  if (short_count_ == nullptr) {
    return false;
  }
  const std::int64_t shorts = short_count_->get();
  std::int64_t pulses = 0;
  for (const Output<std::int64_t>* p : pulse_counts_) {
    const std::int64_t n = p->get();
    if (n < 0 || n > kMaxPulseCount) {
      return true;  // a broken counter: the gap may be short, so nothing toward the work
    }
    pulses += n;
  }
  if (shorts < 0 || shorts > kMaxPulseCount) {
    return true;
  }
  return pulses > 0 && static_cast<double>(shorts) >= short_limit_ * static_cast<double>(pulses);
}

bool Supervisor::referenced(const Axis& a) const noexcept {
  return manual_ == nullptr || a.ref_bit < 0 || (manual_->referenced() >> a.ref_bit & 1U) != 0;
}

bool Supervisor::is_outside(const Axis& a, double x) const noexcept {
  if (!referenced(a)) return false;  // its coordinates are the power-on ones: no range yet
  // The command stops at the limit; the mechanics may overshoot it by their dynamic error,
  // which the following-error band at standstill (min_ferror_mm) allows for.
  const double tol = std::max(kEpsilon, a.cfg.min_ferror_mm);
  return !(x >= a.cfg.limits.min_mm - tol && x <= a.cfg.limits.max_mm + tol);
}

void Supervisor::check_axis(Axis& a, TimePoint now, bool track) noexcept {
  const double x = a.cfg.position->get();
  const machining::AxisLimits& lim = a.cfg.limits;

  double ferror = 0.0;
  bool ferror_over = false;
  if (track && a.tracking && a.cfg.ferror_mm > 0.0) {
    ferror = std::abs(a.x_cmd_mm - x);
    const double share = std::min(1.0, std::abs(a.v_cmd_mm_s) / lim.v_max_mm_s);
    const double allowed = a.cfg.min_ferror_mm + (a.cfg.ferror_mm - a.cfg.min_ferror_mm) * share;
    ferror_over = !(ferror <= allowed);  // a NaN position is an error too
  }
  a.ferror_now_mm.store(ferror, std::memory_order_relaxed);
  condition(ferror_over, a.ferror_raised,
            make_alarm(AlarmCode::kFollowingError, AlarmSeverity::kFault, now, a.source.c_str(),
                       "following error: the axis lags its command beyond its limit", ferror));
  if (!track || !a.tracking) {
    a.x_cmd_mm = x;  // (re)start the model where the axis is
    a.v_cmd_mm_s = 0.0;
    a.v_target_mm_s = 0.0;
    a.tracking = track;
  }

  // Outside the range by more than the drive may overshoot a commanded stop (drift, a wrong
  // offset, an axis pushed): alarm; commands that go back in are still allowed (limit_command).
  const bool outside = is_outside(a, x);
  if (outside) {
    a.limit_raised = true;
    machine_.raise(make_alarm(AlarmCode::kSoftLimit, AlarmSeverity::kFault, now, a.source.c_str(),
                              "soft limit: the axis is outside its range", x));
  }
}

double Supervisor::limit_command(Axis& a, TimePoint now) noexcept {
  const double requested = a.cfg.velocity->requested();
  const machining::AxisLimits& lim = a.cfg.limits;
  const double x = a.cfg.position->get();
  double v = std::isfinite(requested) ? requested : 0.0;

  const bool too_fast = std::abs(v) > lim.v_max_mm_s + kEpsilon;
  if (too_fast) {
    v = std::clamp(v, -lim.v_max_mm_s, lim.v_max_mm_s);
  }
  condition(too_fast, a.speed_raised,
            make_alarm(AlarmCode::kSoftLimit, AlarmSeverity::kWarning, now, a.speed_source.c_str(),
                       "soft limit: velocity command above v_max_mm_s clamped", requested));

  // A command the axis could not stop from inside the range is cut to one it can.
  const double d = v > 0.0 ? lim.max_mm - x : x - lim.min_mm;
  const double allowed = !std::isfinite(x) ? 0.0
                         : !referenced(a)  ? lim.v_max_mm_s
                                           : stop_speed(d, lim.a_max_mm_s2, dt_s_);
  const bool refused = std::abs(v) > allowed + kEpsilon;
  if (refused) {
    v = v > 0.0 ? allowed : -allowed;
  }
  const bool outside = is_outside(a, x);
  if (refused) {
    machine_.raise(make_alarm(AlarmCode::kSoftLimit, AlarmSeverity::kFault, now, a.source.c_str(),
                              "soft limit: a velocity command beyond the range was refused",
                              requested));
    a.limit_raised = true;
  } else if (!outside && a.limit_raised) {
    machine_.clear_alarm(AlarmCode::kSoftLimit, a.source.c_str());
    a.limit_raised = false;
  }
  if (too_fast || refused) {
    refused_cycles_.fetch_add(1, std::memory_order_relaxed);
  }
  return v;
}

void Supervisor::advance_model(Axis& a, double v) const noexcept {
  const double dv = a.cfg.limits.a_max_mm_s2 * dt_s_;
  a.v_cmd_mm_s += std::clamp(v - a.v_cmd_mm_s, -dv, dv);
  a.x_cmd_mm += a.v_cmd_mm_s * dt_s_;
}

std::int64_t Supervisor::periods_behind(TimePoint inputs_at) noexcept {
  if (!have_model_time_ || period_.count() <= 0) {
    have_model_time_ = true;
    model_at_ = inputs_at;
    return 0;
  }
  if (inputs_at - model_at_ > kLongestFollowedGap) {
    model_at_ = inputs_at;
    return -2;  // a pause (the task stopped and started again): restart the models
  }
  // The inputs' age against the model's time, in whole periods (rounded: the wake-up jitter of
  // the real clock is not an omitted cycle).
  const std::int64_t p = period_.count();
  const std::int64_t g = (inputs_at - model_at_).count();
  const std::int64_t n = g >= 0 ? (g + p / 2) / p : -((-g + p / 2) / p);
  return std::max<std::int64_t>(n, -1);
}

void Supervisor::follow_omitted(Axis& a, std::int64_t cycles) const noexcept {
  // The a_max-limited approach to the last command takes at most 2·v_max / (a_max·dt) periods;
  // after that the model moves at that command, so a long gap costs no more than a short one.
  const double v = a.v_target_mm_s;
  for (std::int64_t k = 0; k < cycles; ++k) {
    if (std::abs(v - a.v_cmd_mm_s) <= 1e-12) {
      a.v_cmd_mm_s = v;
      a.x_cmd_mm += v * dt_s_ * static_cast<double>(cycles - k);
      return;
    }
    advance_model(a, v);
  }
}

void Supervisor::supervise(const CycleContext& ctx, TimePoint inputs_at) noexcept {
  const MachineState before = machine_.state();
  bool track = before != MachineState::kOff && !is_safe_state(before);
  if (manual_ != nullptr) {
    const std::uint64_t epoch = manual_->position_epoch();
    if (epoch != epoch_seen_) {  // an encoder was set: the readings jumped, restart the models
      epoch_seen_ = epoch;
      for (Axis& a : axes_) a.tracking = false;
    }
  }
  // Omitted cycles (a late cycle, a host that did not run the task): the drives followed the
  // last command until these inputs were read, and so does the model.
  const std::int64_t behind = periods_behind(inputs_at);
  for (Axis& a : axes_) {
    if (behind == -2) {
      a.tracking = false;  // check_axis restarts the model where the axis is
    } else if (a.tracking && behind > 0) {
      follow_omitted(a, behind);
    }
  }
  if (behind > 0) {
    model_at_ += behind * period_;
  }
  check_machine(ctx.release);
  for (Axis& a : axes_) {
    check_axis(a, ctx.release, track);
  }
  for (std::size_t k = 0; k < axes_.size(); ++k) {
    command_[k] = limit_command(axes_[k], ctx.release);
  }

  // The same-cycle short stop: a cycle whose own pulses read short commands nothing toward
  // the work (against an axis's retract direction), whatever the programs' windows say.
  const bool short_now = cycle_reads_short();
  if (short_now) {
    short_cycles_.fetch_add(1, std::memory_order_relaxed);
    bool cut = false;
    for (std::size_t k = 0; k < axes_.size(); ++k) {
      const double way = static_cast<double>(axes_[k].cfg.retract);
      if (way != 0.0 && command_[k] * way < 0.0) {
        command_[k] = 0.0;
        cut = true;
      }
    }
    if (cut) {
      short_stopped_cycles_.fetch_add(1, std::memory_order_relaxed);
    }
  }

  // The state now, after this cycle's alarms: a fault found above stops the axes in this cycle.
  const MachineState s = machine_.state();
  for (std::size_t k = 0; k < axes_.size(); ++k) {
    Axis& a = axes_[k];
    double v = command_[k];
    if (s == MachineState::kEstop) {
      v = 0.0;
    } else if (s == MachineState::kFault) {
      const double way = static_cast<double>(a.cfg.retract);
      v = v * way > 0.0 ? v : 0.0;
    }
    const double requested = a.cfg.velocity->requested();
    if (v != requested) {  // also true for a NaN request
      a.cfg.velocity->supervise(v);
    } else {
      a.cfg.velocity->end_supervision();
    }
    if (a.tracking && !is_safe_state(s)) {
      a.v_target_mm_s = v;
      if (behind != -1) {  // -1: these inputs came a period early (after a late cycle): wait
        advance_model(a, v);
      }
    } else {
      a.tracking = false;
    }
  }
  if (behind != -1) {
    model_at_ += period_;  // the models now stand for the next cycle's inputs, one period on
  }
  const bool safe = is_safe_state(s);
  for (Input<bool>* g : generator_) {
    if (safe) {
      g->supervise(false);
    } else {
      g->end_supervision();
    }
  }
}

}  // namespace edm::rt
