#include "edm/programs/wire_cut.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "edm/blocks/param_ranges.hpp"

namespace edm::programs {
namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kFullCircleMm = 1e-6;
}  // namespace

void WireCutParams::visit(rt::ParamVisitor& v) {
  namespace r = blocks::ranges;
  v.param("kv_mm_s_per_v", kv_mm_s_per_v,
          {"mm/s/V", "path speed per volt of mean gap voltage above the servo reference",
           rt::open_closed(0.0, 1.0)});
  v.param("u_tau", u_tau, {"s", "time constant of the mean gap voltage's filter", r::kSettleS});
  v.param("back_speed_mm_s", back_speed_mm_s,
          {"mm/s", "speed back along the path on a short", r::kSpeedMmS});
  v.param("back_min_mm", back_min_mm,
          {"mm", "a short backs the wire up at least this far", rt::open_closed(0.0, 5.0)});
  v.param("ramp_mm_s2", ramp_mm_s2, {"mm/s2", "rise of the forward path speed", r::kAccelMmS2});
  v.param("short_fraction", short_fraction,
          {"1", "a cycle with this share of short pulses reads short", rt::open_closed(0.0, 1.0)});
}

void WireCut::activate() noexcept {
  reset();
  shorts.set(0);
  path_speed_mm_s.set(0.0);
  back_mm.set(0.0);
  block_done_mm.set(0.0);
  shorted.set(false);
}

void WireCut::reset() noexcept {
  head_ = count_ = 0;
  since_push_ = 0.0;
  back_ = retreat_ = v_ = 0.0;
  u_init_ = false;
}

void WireCut::begin(const machining::MotionBlock& b, double x0, double y0,
                    bool continuing) noexcept {
  if (!continuing) reset();
  arc_ = b.kind == machining::MotionKind::kArcCw || b.kind == machining::MotionKind::kArcCcw;
  cw_ = b.kind == machining::MotionKind::kArcCw;
  x0_ = x0;
  y0_ = y0;
  x1_ = b.target.x;
  y1_ = b.target.y;
  cx_ = b.centre.x;
  cy_ = b.centre.y;
  if (arc_) {
    r_ = std::hypot(x0 - cx_, y0 - cy_);
    a0_ = std::atan2(y0 - cy_, x0 - cx_);
    double sweep = std::atan2(y1_ - cy_, x1_ - cx_) - a0_;
    const bool full = std::hypot(x1_ - x0, y1_ - y0) <= kFullCircleMm;
    if (cw_) {
      while (sweep >= 0.0) sweep -= kTwoPi;
      if (full) sweep = -kTwoPi;
    } else {
      while (sweep <= 0.0) sweep += kTwoPi;
      if (full) sweep = kTwoPi;
    }
    sweep_ = sweep;
    length_ = r_ * std::abs(sweep);
  } else {
    length_ = std::hypot(x1_ - x0, y1_ - y0);
  }
  s_ = 0.0;
  if (count_ == 0) push_history(x0, y0);
  double tx = 0.0, ty = 0.0;
  point_at(0.0, ref_x_, ref_y_, tx, ty);
  if (back_ > 0.0) history_point(back_, ref_x_, ref_y_, tx, ty);
  vx_ = vy_ = 0.0;
  block_done_mm.set(0.0);
}

void WireCut::point_at(double s, double& x, double& y, double& tx, double& ty) const noexcept {
  if (arc_) {
    const double sign = sweep_ < 0.0 ? -1.0 : 1.0;
    const double a = a0_ + sign * s / r_;
    x = cx_ + r_ * std::cos(a);
    y = cy_ + r_ * std::sin(a);
    tx = -sign * std::sin(a);
    ty = sign * std::cos(a);
    return;
  }
  const double f = length_ > 0.0 ? s / length_ : 1.0;
  x = x0_ + (x1_ - x0_) * f;
  y = y0_ + (y1_ - y0_) * f;
  tx = length_ > 0.0 ? (x1_ - x0_) / length_ : 0.0;
  ty = length_ > 0.0 ? (y1_ - y0_) / length_ : 0.0;
}

void WireCut::push_history(double x, double y) noexcept {
  head_ = (head_ + 1) & (kHistoryPoints - 1);
  hx_[head_] = x;
  hy_[head_] = y;
  count_ = std::min(count_ + 1, kHistoryPoints);
  since_push_ = 0.0;
}

double WireCut::history_mm() const noexcept {
  return since_push_ + static_cast<double>(count_ > 0 ? count_ - 1 : 0) * kHistoryStepMm;
}

void WireCut::history_point(double back, double& x, double& y, double& tx,
                            double& ty) const noexcept {
  double fx = 0.0, fy = 0.0, ftx = 0.0, fty = 0.0;
  point_at(s_, fx, fy, ftx, fty);  // the frontier
  double ax = fx, ay = fy, seg = since_push_;
  std::size_t k = head_;
  double left = back;
  std::size_t steps = 0;
  while (true) {
    const double bx = hx_[k], by = hy_[k];
    if (left <= seg || steps + 1 >= count_) {
      const double f = seg > 0.0 ? std::min(1.0, left / seg) : 0.0;
      x = ax + (bx - ax) * f;
      y = ay + (by - ay) * f;
      const double d = std::hypot(ax - bx, ay - by);
      tx = d > 0.0 ? (ax - bx) / d : ftx;
      ty = d > 0.0 ? (ay - by) / d : fty;
      return;
    }
    left -= seg;
    ax = bx;
    ay = by;
    seg = kHistoryStepMm;
    k = (k + kHistoryPoints - 1) & (kHistoryPoints - 1);
    ++steps;
  }
}

bool WireCut::step(double dt_s, double gap_voltage_v, double servo_ref_v, std::int64_t n_short,
                   std::int64_t n_pulses, double cap_mm_s, bool hold) noexcept {
  const double tau = rt::to_seconds(params_.u_tau);
  if (!u_init_) {
    u_f_ = gap_voltage_v;
    u_init_ = true;
  } else {
    u_f_ += (gap_voltage_v - u_f_) * (tau > 0.0 ? std::min(1.0, dt_s / tau) : 1.0);
  }
  const bool is_short = n_pulses > 0 && static_cast<double>(n_short) >=
                                            params_.short_fraction * static_cast<double>(n_pulses);
  shorted.set(is_short);
  if (is_short && retreat_ <= 0.0) {
    shorts.set(shorts.get() + 1);
    retreat_ = params_.back_min_mm;
  } else if (is_short) {
    retreat_ = std::max(retreat_, 0.5 * params_.back_min_mm);  // still short: keep backing
  }
  double v = 0.0;
  if (hold) {
    v = 0.0;
  } else if (retreat_ > 0.0) {
    v = -params_.back_speed_mm_s;
  } else {
    const double servo = params_.kv_mm_s_per_v * (u_f_ - servo_ref_v);
    v = std::clamp(servo, -params_.back_speed_mm_s, std::max(cap_mm_s, 0.0));
    if (v > v_) v = std::min(v, std::max(v_, 0.0) + params_.ramp_mm_s2 * dt_s);
  }
  if (is_short) v = std::min(v, 0.0);  // never forward while the gap reads short
  double ds = v * dt_s;
  if (ds < 0.0) {
    const double room = history_mm() - back_;
    if (-ds > room) ds = -room;  // the end of the history: stand still there
    back_ -= ds;
    retreat_ = std::max(0.0, retreat_ + ds);
    if (room <= 0.0) retreat_ = 0.0;
  } else if (ds > 0.0) {
    const double make_up = std::min(ds, back_);
    back_ -= make_up;
    double fwd = ds - make_up;
    while (fwd > 0.0 && s_ < length_) {  // the frontier advances, recording the history
      const double d = std::min({fwd, length_ - s_, kHistoryStepMm - since_push_});
      s_ += d;
      since_push_ += d;
      fwd -= d;
      if (since_push_ >= kHistoryStepMm - 1e-12) {
        double x = 0.0, y = 0.0, tx = 0.0, ty = 0.0;
        point_at(s_, x, y, tx, ty);
        push_history(x, y);
      }
    }
  }
  v_ = ds / std::max(dt_s, 1e-9);
  double tx = 0.0, ty = 0.0;
  if (back_ > 0.0) {
    history_point(back_, ref_x_, ref_y_, tx, ty);
  } else {
    point_at(s_, ref_x_, ref_y_, tx, ty);
  }
  vx_ = v_ * tx;
  vy_ = v_ * ty;
  path_speed_mm_s.set(v_);
  back_mm.set(back_);
  block_done_mm.set(s_);
  return s_ >= length_ && back_ <= 0.0;
}

}  // namespace edm::programs
