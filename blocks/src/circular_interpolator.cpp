#include "edm/blocks/circular_interpolator.hpp"

#include <cmath>
#include <numbers>

namespace edm::blocks {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}  // namespace

void CircularInterpolator::activate() noexcept {
  x_ = params_.x0_mm;
  y_ = params_.y0_mm;
  cx_ = x_;
  cy_ = y_;
  ex_abs_ = x_;
  ey_abs_ = y_;
  radius_ = 0.0;
  theta0_ = 0.0;
  theta_ = 0.0;
  sigma_ = 1.0;
  sweep_ = 0.0;
  phi_ = 0.0;
  reset_move();
  publish(0.0, 0.0);
}

bool CircularInterpolator::load_position() noexcept {
  const double lx = load_x_mm.get();
  const double ly = load_y_mm.get();
  if (!std::isfinite(lx) || !std::isfinite(ly)) {
    return false;
  }
  x_ = lx;
  y_ = ly;
  return true;
}

bool CircularInterpolator::latch_move() noexcept {
  const double i = i_mm.get();
  const double j = j_mm.get();
  const double feed_mm_min_now = feed_mm_min.get();
  const bool full = full_circle.get();
  const double ex = ex_mm.get();
  const double ey = ey_mm.get();
  if (!std::isfinite(i) || !std::isfinite(j) || !std::isfinite(feed_mm_min_now) ||
      !(feed_mm_min_now > 0.0)) {
    return false;
  }
  const double r = std::hypot(i, j);
  const double cx = x_ + i;
  const double cy = y_ + j;
  if (!(r > 0.0) || !std::isfinite(r) || !std::isfinite(cx) || !std::isfinite(cy)) {
    return false;
  }
  const double theta0 = std::atan2(-j, -i);
  const double sigma = cw.get() ? -1.0 : 1.0;
  double sweep = 0.0;
  double end_x = x_;
  double end_y = y_;
  if (full) {
    const std::int64_t turns_now = turns.get();
    if (turns_now < 1 || turns_now > kMaxTurns) {
      return false;
    }
    sweep = kTwoPi * static_cast<double>(turns_now);
  } else {
    if (!std::isfinite(ex) || !std::isfinite(ey)) {
      return false;
    }
    if (ex == 0.0 && ey == 0.0) {
      sweep = kTwoPi;
    } else {
      end_x = x_ + ex;
      end_y = y_ + ey;
      // End relative to the centre, from the increments so that C's rounding does not enter.
      const double dx = ex - i;
      const double dy = ey - j;
      const double r_end = std::hypot(dx, dy);
      if (!std::isfinite(r_end) || !(std::abs(r_end - r) <= params_.end_tol_mm)) {
        return false;
      }
      double d = sigma * (std::atan2(dy, dx) - theta0);  // in (−2π, 2π)
      d = std::fmod(d, kTwoPi);
      if (d <= 0.0) {
        d += kTwoPi;
      }
      sweep = d;
    }
  }
  cx_ = cx;
  cy_ = cy;
  ex_abs_ = end_x;
  ey_abs_ = end_y;
  radius_ = r;
  theta0_ = theta0;
  theta_ = theta0;
  sigma_ = sigma;
  sweep_ = sweep;
  phi_ = 0.0;
  begin_move(feed_mm_min_now);
  return true;
}

void CircularInterpolator::advance(double ds_mm) noexcept {
  const double phi_next = phi_ + ds_mm / radius_;  // Δθ = fr/R
  double nx = 0.0;
  double ny = 0.0;
  if (phi_next >= sweep_) {
    phi_ = sweep_;
    theta_ = theta0_ + sigma_ * sweep_;
    nx = ex_abs_;
    ny = ey_abs_;
    finish_move();
  } else {
    phi_ = phi_next;
    theta_ = theta0_ + sigma_ * phi_next;
    // (i, j) = −R·(cos θ, sin θ); the point is C − (i, j).
    nx = cx_ + radius_ * std::cos(theta_);
    ny = cy_ + radius_ * std::sin(theta_);
  }
  const double vx = (nx - x_) / dt_s_;
  const double vy = (ny - y_) / dt_s_;
  x_ = nx;
  y_ = ny;
  publish(vx, vy);
}

void CircularInterpolator::publish(double vx_mm_s_now, double vy_mm_s_now) noexcept {
  rx_mm.set(x_);
  ry_mm.set(y_);
  vx_mm_s.set(vx_mm_s_now);
  vy_mm_s.set(vy_mm_s_now);
  angle_rad.set(std::remainder(theta_, kTwoPi));
  swept_rad.set(phi_);
  busy.set(busy_state_);
  done.set(done_state_);
}

}  // namespace edm::blocks
