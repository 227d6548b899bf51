#pragma once
// CircularInterpolator: arcs and full circles in XY, one per rising edge of `start` (SEEDS 004,
// eq. 14–19; G03 counter-clockwise, G02 clockwise).
//
//   on a rising edge of start (and not busy): latch (i, j) [mm] (current point → centre), cw,
//       feed, and the end: full_circle → `turns` revolutions back to the start point; otherwise
//       the end point P0 + (ex, ey) (ex = ey = 0 is one full circle, as in G-code).
//       R = √(i² + j²), C = P0 + (i, j), θ0 = atan2(−j, −i), σ = +1 (G03) or −1 (G02)
//   each cycle while busy and not hold:
//       fr = feed/60 · clamp(override, 0, 2) · dt;   Δθ = fr/R;   φ += Δθ
//       (i, j) = −R·(cos θ, sin θ),  θ = θ0 + σ·φ;   R_xy = C − (i, j)
//       once φ ≥ sweep: R_xy = end point exactly, busy = false, done = true
//
// Eq. 14–19 (Pa = 1 − cos Δθ, Pb = σ·sin Δθ, V = (Pa·i + Pb·j, −Pb·i + Pa·j), R += V, (i, j) −= V)
// rotate (i, j) by σ·Δθ each sample. Iterated as written, the rounding of each rotation grows the
// radius error without bound; here (i, j) is recomputed from the swept angle φ every sample, which
// is the same sequence in exact arithmetic but keeps the radius error at ~1 ulp of R at any
// sample, and the end point is snapped exactly. An end point off the circle by more than
// end_tol_mm is refused; within it the last step lands on the programmed point.
//
// Outputs: position, v = step/dt, angle_rad = θ wrapped to [−π, π] (polar angle of the point seen
// from the centre: the radial direction), swept_rad = φ. `done` is a level (see
// LinearInterpolator); `load` sets the position and cancels a move (the commands are
// MoveInterpolator's).
//
// Status: kSaturated when override was clamped; kFault (no advance, v = 0) on a non-finite
// override or load position, or a rejected move (non-finite inputs, R = 0, feed ≤ 0, turns
// outside [1, kMaxTurns] with full_circle, end point off the circle).
// RT-safe: update(), enter_safe_state() (cancels the move). Not thread-safe: the owning task
// calls every member except the pins (see pin.hpp).

#include <cstdint>

#include "edm/blocks/move_interpolator.hpp"
#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct CircularInterpolatorParams {
  double x0_mm{0.0};        // [mm] position after configure()/activate()
  double y0_mm{0.0};        // [mm]
  double end_tol_mm{1e-3};  // [mm] allowed | |end − C| − R |, ≥ 0

  void visit(rt::ParamVisitor& v) {
    v.param("x0_mm", x0_mm, {"mm", "X position at activation", ranges::kPositionMm});
    v.param("y0_mm", y0_mm, {"mm", "Y position at activation", ranges::kPositionMm});
    v.param(
        "end_tol_mm", end_tol_mm,
        {"mm", "largest accepted difference between the end point's radius and the start radius",
         ranges::kToleranceMm});
  }
};

class CircularInterpolator final : public MoveInterpolator<CircularInterpolatorParams> {
 public:
  static constexpr std::int64_t kMaxTurns = 1'000'000;
  /// Non-RT. Position = (x0, y0), idle.
  void activate() noexcept override;

  // Pins (listed in declaration order; start, feed_mm_min, override, hold, load, busy and done are
  // MoveInterpolator's): a C++ PROGRAM connects them by member.
  rt::Input<bool> cw{pins_, "cw"};
  rt::Input<double> i_mm{pins_, "i_mm", "mm"};
  rt::Input<double> j_mm{pins_, "j_mm", "mm"};
  rt::Input<bool> full_circle{pins_, "full_circle"};
  rt::Input<std::int64_t> turns{pins_, "turns", "", 1};
  rt::Input<double> ex_mm{pins_, "ex_mm", "mm"};
  rt::Input<double> ey_mm{pins_, "ey_mm", "mm"};
  rt::Input<double> load_x_mm{pins_, "load_x_mm", "mm"};
  rt::Input<double> load_y_mm{pins_, "load_y_mm", "mm"};
  rt::Output<double> rx_mm{pins_, "rx_mm", "mm"};
  rt::Output<double> ry_mm{pins_, "ry_mm", "mm"};
  rt::Output<double> vx_mm_s{pins_, "vx_mm_s", "mm/s"};
  rt::Output<double> vy_mm_s{pins_, "vy_mm_s", "mm/s"};
  rt::Output<double> angle_rad{pins_, "angle_rad", "rad"};
  rt::Output<double> swept_rad{pins_, "swept_rad", "rad"};

 private:
  [[nodiscard]] bool load_position() noexcept override;
  [[nodiscard]] bool latch_move() noexcept override;
  void advance(double ds_mm) noexcept override;
  void publish_at_rest() noexcept override { publish(0.0, 0.0); }
  void publish(double vx_mm_s, double vy_mm_s) noexcept;

  double x_{0.0};  // [mm] current position
  double y_{0.0};
  double cx_{0.0};  // [mm] centre
  double cy_{0.0};
  double ex_abs_{0.0};  // [mm] end point
  double ey_abs_{0.0};
  double radius_{0.0};  // [mm]
  double theta0_{0.0};  // [rad] polar angle of the start point about the centre
  double theta_{0.0};   // [rad] current polar angle (unwrapped)
  double sigma_{1.0};   // +1 G03 (ccw), −1 G02 (cw)
  double sweep_{0.0};   // [rad] total angle of the move, > 0
  double phi_{0.0};     // [rad] swept so far
};

}  // namespace edm::blocks
