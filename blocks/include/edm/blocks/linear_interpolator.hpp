#pragma once
// LinearInterpolator: straight-line moves in XYZ, one per rising edge of `start` (SEEDS 004,
// eq. 12–13, generalised to three axes).
//
//   on a rising edge of start (and not busy): latch L = (lx, ly, lz) [mm] and feed [mm/min],
//       P0 = current position, l = √(lx² + ly² + lz²), s = 0
//   each cycle while busy and not hold:
//       fr = feed/60 · clamp(override, 0, 2) · dt        [mm this sample]
//       s += fr;  R = P0 + (s/l)·L                        (= Σ fr·l_axis/l of eq. 12–13)
//       once s ≥ l: R = P0 + L exactly, busy = false, done = true
//   v = (R − R_prev)/dt each cycle (0 when not moving)
//
// The position is computed from the travelled length s rather than summed per axis, so there is
// no rounding growth along the move and the end point is bit-exact P0 + L. `load` (level) sets
// the position to (load_x, load_y, load_z) and cancels a move in progress. A rising start edge
// while busy is ignored. `done` is a level: true from the cycle the end point is reached until
// the next move is latched or a load. A zero-length move completes on its start edge. The
// commands (start, load, hold, override) are MoveInterpolator's.
//
// Status: kSaturated when override was outside [0, 2] (clamped); kFault (no advance, v = 0) on
// a non-finite override or load position, or a rejected move (non-finite increments or feed,
// feed ≤ 0 with l > 0).
// RT-safe: update(), enter_safe_state() (cancels the move). Not thread-safe: the owning task
// calls every member except the pins (see pin.hpp).

#include <array>

#include "edm/blocks/move_interpolator.hpp"
#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/xyz_pins.hpp"

namespace edm::blocks {

struct LinearInterpolatorParams {
  double x0_mm{0.0};  // [mm] position after configure()/activate()
  double y0_mm{0.0};  // [mm]
  double z0_mm{0.0};  // [mm]

  void visit(rt::ParamVisitor& v) {
    v.param("x0_mm", x0_mm, {"mm", "X position at activation", ranges::kPositionMm});
    v.param("y0_mm", y0_mm, {"mm", "Y position at activation", ranges::kPositionMm});
    v.param("z0_mm", z0_mm, {"mm", "Z position at activation", ranges::kPositionMm});
  }
};

class LinearInterpolator final : public MoveInterpolator<LinearInterpolatorParams> {
 public:
  /// Non-RT. Position = (x0, y0, z0), idle.
  void activate() noexcept override;

  // Pins (listed in declaration order; start, feed_mm_min, override, hold, load, busy and done are
  // MoveInterpolator's): a C++ PROGRAM connects them by member.
  rt::Xyz<rt::Input<double>> length{pins_, {"lx_mm", "ly_mm", "lz_mm"}, "mm"};  // L
  rt::Xyz<rt::Input<double>> load_pos{pins_, {"load_x_mm", "load_y_mm", "load_z_mm"}, "mm"};
  rt::Xyz<rt::Output<double>> ref_pos{pins_, {"rx_mm", "ry_mm", "rz_mm"}, "mm"};  // R
  rt::Xyz<rt::Output<double>> vel{pins_, {"vx_mm_s", "vy_mm_s", "vz_mm_s"}, "mm/s"};

 private:
  using Vec3 = std::array<double, 3>;

  [[nodiscard]] bool load_position() noexcept override;
  [[nodiscard]] bool latch_move() noexcept override;
  void advance(double ds_mm) noexcept override;
  void publish_at_rest() noexcept override { publish({}); }
  void publish(const Vec3& v_mm_s) noexcept;

  Vec3 pos_{};       // [mm] current position
  Vec3 p0_{};        // [mm] position when the move was latched
  Vec3 l_{};         // [mm] latched increments
  Vec3 end_{};       // [mm] p0_ + l_
  double len_{0.0};  // [mm] |l_|
  double s_{0.0};    // [mm] path length travelled
};

}  // namespace edm::blocks
