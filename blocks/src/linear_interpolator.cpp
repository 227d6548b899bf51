#include "edm/blocks/linear_interpolator.hpp"

#include <cmath>

namespace edm::blocks {

void LinearInterpolator::activate() noexcept {
  pos_ = {params_.x0_mm, params_.y0_mm, params_.z0_mm};
  p0_ = pos_;
  end_ = pos_;
  l_ = {};
  len_ = 0.0;
  s_ = 0.0;
  reset_move();
  publish({});
}

bool LinearInterpolator::load_position() noexcept {
  const Vec3 p{load_pos.x().get(), load_pos.y().get(), load_pos.z().get()};
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
    return false;
  }
  pos_ = p;
  return true;
}

bool LinearInterpolator::latch_move() noexcept {
  const Vec3 l{length.x().get(), length.y().get(), length.z().get()};
  const double feed_mm_min_now = feed_mm_min.get();
  if (!std::isfinite(l[0]) || !std::isfinite(l[1]) || !std::isfinite(l[2]) ||
      !std::isfinite(feed_mm_min_now)) {
    return false;
  }
  const double len = std::hypot(l[0], l[1], l[2]);
  if (!std::isfinite(len)) {
    return false;
  }
  p0_ = pos_;
  l_ = l;
  for (std::size_t a = 0; a < 3; ++a) {
    end_[a] = p0_[a] + l_[a];
    if (!std::isfinite(end_[a])) {
      return false;
    }
  }
  len_ = len;
  s_ = 0.0;
  if (len == 0.0) {  // zero-length move: complete at once, the feed is not needed
    finish_move();
    return true;
  }
  if (!(feed_mm_min_now > 0.0)) {
    return false;
  }
  begin_move(feed_mm_min_now);
  return true;
}

void LinearInterpolator::advance(double ds_mm) noexcept {
  const double s_next = s_ + ds_mm;
  Vec3 next{};
  if (s_next >= len_) {
    next = end_;
    s_ = len_;
    finish_move();
  } else {
    const double u = s_next / len_;
    for (std::size_t a = 0; a < 3; ++a) {
      next[a] = p0_[a] + u * l_[a];
    }
    s_ = s_next;
  }
  Vec3 v{};
  for (std::size_t a = 0; a < 3; ++a) {
    v[a] = (next[a] - pos_[a]) / dt_s_;
  }
  pos_ = next;
  publish(v);
}

void LinearInterpolator::publish(const Vec3& v_mm_s) noexcept {
  for (std::size_t a = 0; a < rt::kAxes; ++a) {
    ref_pos[a].set(pos_[a]);
    vel[a].set(v_mm_s[a]);
  }
  busy.set(busy_state_);
  done.set(done_state_);
}

}  // namespace edm::blocks
