// Arc extent for the soft-limit check; see gcode_arc.hpp.

#include "gcode_arc.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace edm::hmi::detail {

double ccw_sweep(double a0, double a1) noexcept {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  double s = std::fmod(a1 - a0, kTwoPi);
  if (s <= 0.0) s += kTwoPi;
  return s;
}

ArcBox arc_bounding_box(double sx, double sy, double ex, double ey, bool clockwise,
                        bool full) noexcept {
  const double r = std::hypot(sx, sy);
  ArcBox box{std::min(sx, ex), std::max(sx, ex), std::min(sy, ey), std::max(sy, ey)};
  const double a0 = std::atan2(sy, sx);
  const double a1 = std::atan2(ey, ex);
  // Going clockwise from a0 to a1 sweeps the same points as counter-clockwise from a1 to a0.
  const double from = clockwise ? a1 : a0;
  const double sweep = full ? 2.0 * std::numbers::pi : ccw_sweep(from, clockwise ? a0 : a1);
  for (int k = 0; k < 4; ++k) {
    const double a = k * std::numbers::pi / 2.0;
    // An axis direction a lies on the arc when it is reached from `from` within the sweep.
    if (full || ccw_sweep(from, a) <= sweep) {
      switch (k) {
        case 0:
          box.max_x = std::max(box.max_x, r);
          break;
        case 1:
          box.max_y = std::max(box.max_y, r);
          break;
        case 2:
          box.min_x = std::min(box.min_x, -r);
          break;
        default:
          box.min_y = std::min(box.min_y, -r);
          break;
      }
    }
  }
  return box;
}

}  // namespace edm::hmi::detail
