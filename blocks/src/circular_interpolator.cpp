#include "edm/blocks/circular_interpolator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "edm/blocks/validation.hpp"

namespace edm::blocks {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}  // namespace

std::vector<rt::ParamError> CircularInterpolatorParams::validate() const {
  std::vector<rt::ParamError> errs;
  rt::require_finite(errs, "x0_mm", x0_mm);
  rt::require_finite(errs, "y0_mm", y0_mm);
  rt::require_finite(errs, "end_tol_mm", end_tol_mm);
  if (std::isfinite(end_tol_mm)) {
    rt::require_non_negative(errs, "end_tol_mm", end_tol_mm);
  }
  return errs;
}

void CircularInterpolator::visit_pins(rt::PinVisitor& v) {
  v.input("start", start_);
  v.input("cw", cw_);
  v.input("i_mm", i_, "mm");
  v.input("j_mm", j_, "mm");
  v.input("full_circle", full_circle_);
  v.input("turns", turns_);
  v.input("ex_mm", ex_, "mm");
  v.input("ey_mm", ey_, "mm");
  v.input("feed_mm_min", feed_, "mm/min");
  v.input("override", override_);
  v.input("hold", hold_);
  v.input("load", load_);
  v.input("load_x_mm", load_x_, "mm");
  v.input("load_y_mm", load_y_, "mm");
  v.output("rx_mm", rx_, "mm");
  v.output("ry_mm", ry_, "mm");
  v.output("vx_mm_s", vx_, "mm/s");
  v.output("vy_mm_s", vy_, "mm/s");
  v.output("angle_rad", angle_, "rad");
  v.output("swept_rad", swept_, "rad");
  v.output("busy", busy_);
  v.output("done", done_);
}

std::vector<rt::ParamError> CircularInterpolator::configure(const rt::BlockSetup& setup) {
  std::vector<rt::ParamError> errs;
  require_task_period(errs, setup.period);
  dt_s_ = rt::to_seconds(setup.period);
  activate();
  return errs;
}

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
  feed_mm_s_ = 0.0;
  busy_state_ = false;
  done_state_ = false;
  prev_start_ = false;
  publish(0.0, 0.0);
}

void CircularInterpolator::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  busy_state_ = false;
  done_state_ = false;
  publish(0.0, 0.0);
}

bool CircularInterpolator::latch_move() noexcept {
  const double i = i_.get();
  const double j = j_.get();
  const double feed_mm_min = feed_.get();
  const bool full = full_circle_.get();
  const double ex = ex_.get();
  const double ey = ey_.get();
  if (!std::isfinite(i) || !std::isfinite(j) || !std::isfinite(feed_mm_min) ||
      !(feed_mm_min > 0.0)) {
    return false;
  }
  const double r = std::hypot(i, j);
  const double cx = x_ + i;
  const double cy = y_ + j;
  if (!(r > 0.0) || !std::isfinite(r) || !std::isfinite(cx) || !std::isfinite(cy)) {
    return false;
  }
  const double theta0 = std::atan2(-j, -i);
  const double sigma = cw_.get() ? -1.0 : 1.0;
  double sweep = 0.0;
  double end_x = x_;
  double end_y = y_;
  if (full) {
    const std::int64_t turns = turns_.get();
    if (turns < 1 || turns > kMaxTurns) {
      return false;
    }
    sweep = kTwoPi * static_cast<double>(turns);
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
  feed_mm_s_ = feed_mm_min / 60.0;
  busy_state_ = true;
  done_state_ = false;
  return true;
}

rt::BlockStatus CircularInterpolator::update(const rt::CycleContext& /*ctx*/) noexcept {
  const bool start = start_.get();
  const bool edge = start && !prev_start_;
  prev_start_ = start;

  if (load_.get()) {
    const double lx = load_x_.get();
    const double ly = load_y_.get();
    if (!std::isfinite(lx) || !std::isfinite(ly)) {
      publish(0.0, 0.0);
      return rt::BlockStatus::kFault;
    }
    x_ = lx;
    y_ = ly;
    busy_state_ = false;
    done_state_ = false;
    publish(0.0, 0.0);
    return rt::BlockStatus::kOk;
  }

  if (edge && !busy_state_ && !latch_move()) {
    busy_state_ = false;
    done_state_ = false;
    publish(0.0, 0.0);
    return rt::BlockStatus::kFault;
  }
  if (!busy_state_) {
    publish(0.0, 0.0);
    return rt::BlockStatus::kOk;
  }

  const double ov_in = override_.get();
  if (!std::isfinite(ov_in)) {
    publish(0.0, 0.0);
    return rt::BlockStatus::kFault;
  }
  const double ov = std::clamp(ov_in, 0.0, kMaxOverride);
  const rt::BlockStatus status = ov != ov_in ? rt::BlockStatus::kSaturated : rt::BlockStatus::kOk;
  if (hold_.get()) {
    publish(0.0, 0.0);
    return status;
  }

  const double phi_next = phi_ + feed_mm_s_ * ov * dt_s_ / radius_;  // Δθ = fr/R
  double nx = 0.0;
  double ny = 0.0;
  if (phi_next >= sweep_) {
    phi_ = sweep_;
    theta_ = theta0_ + sigma_ * sweep_;
    nx = ex_abs_;
    ny = ey_abs_;
    busy_state_ = false;
    done_state_ = true;
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
  return status;
}

void CircularInterpolator::publish(double vx_mm_s, double vy_mm_s) noexcept {
  rx_.set(x_);
  ry_.set(y_);
  vx_.set(vx_mm_s);
  vy_.set(vy_mm_s);
  angle_.set(std::remainder(theta_, kTwoPi));
  swept_.set(phi_);
  busy_.set(busy_state_);
  done_.set(done_state_);
}

}  // namespace edm::blocks
