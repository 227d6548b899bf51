#pragma once
// Private to the interpreter: the extent of an XY arc, for the soft-limit check. Pure functions.

namespace edm::hmi::detail {

/// Bounding box of an arc relative to its centre (mm).
struct ArcBox {
  double min_x{0.0};
  double max_x{0.0};
  double min_y{0.0};
  double max_y{0.0};
};

/// The box of the arc from (sx, sy) to (ex, ey) (both relative to the centre) swept clockwise
/// or counter-clockwise; `full` sweeps the whole circle (full circles, extra turns). The radius
/// is the start radius (the end radius agrees within the arc tolerance).
ArcBox arc_bounding_box(double sx, double sy, double ex, double ey, bool clockwise,
                        bool full) noexcept;

/// The angle swept (rad, in (0, 2π]) going from angle a0 to a1 counter-clockwise.
double ccw_sweep(double a0, double a1) noexcept;

}  // namespace edm::hmi::detail
