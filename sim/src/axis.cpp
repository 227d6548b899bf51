#include "edm/sim/axis.hpp"

#include <algorithm>

namespace edm::sim {

void Axis::reset(double pos_mm) noexcept {
  x_mm_ = x_ref_mm_ = pos_mm;
  v_mm_s_ = v_ref_mm_s_ = 0.0;
}

void Axis::step(double v_cmd_mm_s, double dt_s) noexcept {
  const double target = std::clamp(v_cmd_mm_s, -limits_.v_neg_max_mm_s, limits_.v_pos_max_mm_s);
  const double dv_max = limits_.a_max_mm_s2 * dt_s;
  v_ref_mm_s_ += std::clamp(target - v_ref_mm_s_, -dv_max, dv_max);
  x_ref_mm_ += v_ref_mm_s_ * dt_s;
  const double wn = limits_.wn_rad_s;
  const double a =
      wn * wn * (x_ref_mm_ - x_mm_) + 2.0 * limits_.zeta * wn * (v_ref_mm_s_ - v_mm_s_);
  v_mm_s_ += a * dt_s;
  x_mm_ += v_mm_s_ * dt_s;
}

}  // namespace edm::sim
