#pragma once
// One servo axis driven by a velocity command (PLANT-MODEL.md §3, §6.3). Model chosen: the
// position-loop form. The velocity command is clipped (v_max toward the work, v_jump away from
// it), rate-limited by a_max (the drive's trajectory generator) and integrated into a reference
// x_ref; the mechanics follow it as a second-order loop with velocity feed-forward:
//   ẍ = ω_n² (x_ref − x) + 2 ζ ω_n (v_ref − ẋ)
// so a constant velocity is tracked without lag, and steps settle in ≈ 4/(ζ ω_n) (36 ms at the
// defaults). Jerk limiting is not modelled. Semi-implicit Euler, stable for ω_n dt << 1.
//
// RT-safety: all members are noexcept and allocation-free. Thread-safety: one thread.

namespace edm::sim {

struct AxisLimits {
  double wn_rad_s{200.0};
  double zeta{0.55};
  double v_neg_max_mm_s{30.0};  // speed limit in −x (toward the work for z)
  double v_pos_max_mm_s{30.0};  // speed limit in +x (retract for z)
  double a_max_mm_s2{2000.0};
};

class Axis {
 public:
  Axis() = default;
  explicit Axis(const AxisLimits& limits) noexcept : limits_(limits) {}

  /// Puts the axis at rest at pos_mm (reference too).
  void reset(double pos_mm) noexcept;
  /// Advances by dt_s under the velocity command v_cmd_mm_s.
  void step(double v_cmd_mm_s, double dt_s) noexcept;

  [[nodiscard]] double position_mm() const noexcept { return x_mm_; }
  [[nodiscard]] double velocity_mm_s() const noexcept { return v_mm_s_; }
  [[nodiscard]] double reference_mm() const noexcept { return x_ref_mm_; }

 private:
  AxisLimits limits_{};
  double x_mm_{0.0}, v_mm_s_{0.0};
  double x_ref_mm_{0.0}, v_ref_mm_s_{0.0};
};

}  // namespace edm::sim
