#include "edm/blocks/short_retract.hpp"

#include <algorithm>
#include <cmath>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {
namespace {

double distance(double ax, double ay, double az, double bx, double by, double bz) noexcept {
  const double dx = bx - ax;
  const double dy = by - ay;
  const double dz = bz - az;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace

std::vector<rt::ParamError> ShortRetract::configure(const rt::BlockSetup& setup) {
  return configure_checked(params_, setup.period, [&] {
    dt_s_ = rt::to_seconds(setup.period);
    history_.allocate(static_cast<std::size_t>(params_.history_capacity));
    compute_ramp();
    activate();
  });
}

void ShortRetract::activate() noexcept {
  history_.clear();
  state_ = State::kIdle;
  pos_s_ = 0.0;
  target_s_ = 0.0;
  seg_ = 0;
  short_count_ = 0;
  tries_ = 0;
  s_at_short_ = 0.0;
  alarm_ = false;
  final_ = false;
  ramp_k_ = 0;
  retracts.set(0);
  active.set(false);
  v_scale.set(1.0);
  tries.set(0);
  alarm.set(false);
  hold.set(false);
}

void ShortRetract::params_changed() noexcept { compute_ramp(); }

void ShortRetract::compute_ramp() noexcept {
  // floor: full feed is reached within resume_ramp_ms, never one cycle after it.
  const double cycles =
      dt_s_ > 0.0 ? std::floor(params_.resume_ramp_ms * 1e-3 / dt_s_ + 1e-9) : 0.0;
  ramp_cycles_ = static_cast<std::int64_t>(std::clamp(cycles, 0.0, 1.0e12));
}

void ShortRetract::record(double x, double y, double z, bool force) noexcept {
  if (history_.size() == 0) {
    history_.push({x, y, z, 0.0});
    return;
  }
  // A back-off over the last segment unwinds the path instead of doubling it.
  while (history_.size() >= 2) {
    const PathPoint& h = head();
    const PathPoint& p = at(history_.size() - 2);
    const double dot = (x - h.x) * (h.x - p.x) + (y - h.y) * (h.y - p.y) + (z - h.z) * (h.z - p.z);
    if (dot < 0.0 && distance(p.x, p.y, p.z, x, y, z) < h.s - p.s) {
      history_.pop_newest();
    } else {
      break;
    }
  }
  const PathPoint& h = head();
  const double d = distance(h.x, h.y, h.z, x, y, z);
  if (d <= 0.0 || (!force && d < params_.min_spacing_mm)) {
    return;
  }
  history_.push({x, y, z, h.s + d});  // when full, the oldest point leaves
}

void ShortRetract::set_point_at(double s) noexcept {
  const PathPoint& a = at(seg_);
  if (history_.size() < 2 || s <= a.s) {
    sp_[0] = a.x;
    sp_[1] = a.y;
    sp_[2] = a.z;
    return;
  }
  const PathPoint& b = at(seg_ + 1);
  if (s >= b.s) {
    sp_[0] = b.x;
    sp_[1] = b.y;
    sp_[2] = b.z;
    return;
  }
  const double t = (s - a.s) / (b.s - a.s);
  sp_[0] = a.x + t * (b.x - a.x);
  sp_[1] = a.y + t * (b.y - a.y);
  sp_[2] = a.z + t * (b.z - a.z);
}

void ShortRetract::start_retract(bool from_head) noexcept {
  if (from_head) {
    pos_s_ = head().s;
    seg_ = history_.size() >= 2 ? history_.size() - 2 : 0;
    s_at_short_ = pos_s_;
  }
  target_s_ = std::max(pos_s_ - params_.retract_distance_mm, at(0).s);
  state_ = State::kRetract;
  short_count_ = 0;
}

rt::BlockStatus ShortRetract::update(const rt::CycleContext& /*ctx*/) noexcept {
  const ShortRetractParams& p = params_;
  if (history_.capacity() == 0) {  // not configured
    return fault("not configured (no short history)");
  }
  if (reset.get()) {
    alarm_ = false;
    final_ = false;
    tries_ = 0;
    if (state_ == State::kHold) {
      state_ = State::kResume;
    }
  }
  bool input_fault = false;
  double v_scale_now = 1.0;
  if (!enable.get()) {
    state_ = State::kIdle;
    history_.forget();  // O(1): record() never reads a slot it has not written
    short_count_ = 0;
    final_ = false;
    const double x = x_mm.get();
    const double y = y_mm.get();
    const double z = z_mm.get();
    if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) {
      sp_[0] = x;
      sp_[1] = y;
      sp_[2] = z;
    } else {
      input_fault = true;
    }
  } else {
    // Short detection (not while backing off or holding: the short is being dealt with).
    bool sustained = false;
    if (state_ == State::kRetract || state_ == State::kHold) {
      short_count_ = 0;
    } else {
      short_count_ = short_detected.get() ? std::min(short_count_ + 1, p.short_cycles) : 0;
      sustained = short_count_ >= p.short_cycles;
    }
    const bool recording = state_ == State::kIdle || state_ == State::kRamp;
    if (recording) {
      const double x = x_mm.get();
      const double y = y_mm.get();
      const double z = z_mm.get();
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        input_fault = true;
        sustained = false;  // no valid head to retract from this cycle
      } else {
        record(x, y, z, sustained);
        sp_[0] = x;
        sp_[1] = y;
        sp_[2] = z;
        if (head().s - s_at_short_ >= p.progress_mm) {
          tries_ = 0;
        }
      }
    }
    if (sustained) {
      if (tries_ >= p.max_tries) {
        alarm_ = true;
        final_ = true;
      } else {
        ++tries_;
      }
      start_retract(/*from_head=*/recording);
      retracts.set(retracts.get() + 1);
    }

    switch (state_) {
      case State::kIdle: break;
      case State::kRetract: {
        pos_s_ = std::max(pos_s_ - p.retract_speed_mm_s * dt_s_, target_s_);
        while (seg_ > 0 && at(seg_).s > pos_s_) {
          --seg_;
        }
        set_point_at(pos_s_);
        v_scale_now = 0.0;
        if (pos_s_ <= target_s_) {
          state_ = final_ ? State::kHold : State::kResume;
        }
        break;
      }
      case State::kResume: {
        const double s_head = head().s;
        pos_s_ = std::min(pos_s_ + p.resume_speed_mm_s * dt_s_, s_head);
        while (seg_ + 2 < history_.size() && at(seg_ + 1).s < pos_s_) {
          ++seg_;
        }
        v_scale_now = 0.0;
        if (pos_s_ >= s_head) {
          const PathPoint& h = head();
          sp_[0] = h.x;
          sp_[1] = h.y;
          sp_[2] = h.z;
          ramp_k_ = 0;
          state_ = ramp_cycles_ > 0 ? State::kRamp : State::kIdle;
          v_scale_now = ramp_cycles_ > 0 ? 0.0 : 1.0;
        } else {
          set_point_at(pos_s_);
        }
        break;
      }
      case State::kRamp:
        ++ramp_k_;
        if (ramp_k_ >= ramp_cycles_) {
          state_ = State::kIdle;
        } else {
          v_scale_now = static_cast<double>(ramp_k_) / static_cast<double>(ramp_cycles_);
        }
        break;
      case State::kHold: v_scale_now = 0.0; break;
    }
  }
  const bool active_now =
      state_ == State::kRetract || state_ == State::kResume || state_ == State::kHold;
  if (!input_fault || active_now) {
    active.set(active_now);
    x_sp_mm.set(sp_[0]);
    y_sp_mm.set(sp_[1]);
    z_sp_mm.set(sp_[2]);
    v_scale.set(v_scale_now);
  }
  tries.set(tries_);
  alarm.set(alarm_);
  hold.set(alarm_);
  if (input_fault) return fault("a non-finite axis position");
  if (alarm_) {
    return fault("the short persists after max_tries retracts", static_cast<double>(tries_));
  }
  return rt::BlockStatus::kOk;
}

}  // namespace edm::blocks
