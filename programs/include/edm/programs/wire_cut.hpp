#pragma once
// WireCut: the wire machine's machining cycle (docs/runtime.md "Machining cycles"): one cut block
// (a line or an arc of the compensated path, machining::MotionBlock::cut) fed along the path at
// the speed the gap servo sets, and back along the path already cut on a short.
//
// Servo: the path speed follows v = kv (U_f − servo_ref_v), U_f the mean gap voltage through a
// first-order filter (u_tau), capped by the block's feed times the override; a rise is limited
// to ramp_mm_s2 (after a back-up the wire goes forward again on a ramp), a fall is not.
// Short: a cycle whose pulses are ≥ short_fraction shorts reads short; the wire then goes back
// along the path at back_speed_mm_s for at least back_min_mm, and never forward while the gap
// reads short. Backing up follows the path's history (kHistoryPoints points every
// kHistoryStepMm: 8.19 mm), across block boundaries and corners, as long as the cut goes on
// without another kind of block in between; at the end of the history it stands still.
//
// The job (EdmJob) starts a block with begin(), calls step() every cycle and drives the XY
// loops with reference() and velocity(); a block is done when its end is reached with nothing
// to make up behind it. RT-safe: every member but configure is noexcept and allocation-free.

#include <array>
#include <cstdint>

#include "edm/machining/motion_block.hpp"
#include "edm/runtime/block.hpp"

namespace edm::programs {

struct WireCutParams {
  double kv_mm_s_per_v{0.003};  // [mm/s/V] path speed per volt above the servo reference
  rt::Duration u_tau{std::chrono::milliseconds(5)};  // U_f filter
  double back_speed_mm_s{0.1};                       // [mm/s] back along the path on a short
  double back_min_mm{0.02};                          // [mm] a short backs up at least this far
  double ramp_mm_s2{2.0};                            // [mm/s²] rise of the forward speed
  double short_fraction{0.5};  // a cycle with this share of shorts reads short

  void visit(rt::ParamVisitor& v);
};

class WireCut final : public rt::BlockWithParams<WireCutParams> {
 public:
  static constexpr std::size_t kHistoryPoints = 4096;  // power of two: a ring
  static constexpr double kHistoryStepMm = 0.002;
  static_assert((kHistoryPoints & (kHistoryPoints - 1)) == 0);

  rt::Output<double> path_speed_mm_s{pins_, "path_speed_mm_s", "mm/s"};
  rt::Output<double> back_mm{pins_, "back_mm", "mm"};              // behind the furthest point cut
  rt::Output<double> block_done_mm{pins_, "block_done_mm", "mm"};  // of the block running
  rt::Output<std::int64_t> shorts{pins_, "shorts"};                // back-ups since activation
  rt::Output<bool> shorted{pins_, "shorted"};                      // the gap reads short this cycle

  void activate() noexcept override;
  rt::BlockStatus update(const rt::CycleContext& /*ctx*/) noexcept override {
    return rt::BlockStatus::kOk;
  }

  /// Starts cut block `b` from (x0, y0); `continuing`: the previous block was a cut that ended
  /// there, so the history goes on (else it starts afresh).
  void begin(const machining::MotionBlock& b, double x0, double y0, bool continuing) noexcept;
  /// One cycle: the mean gap voltage, the cycle's shorts and pulses, the speed cap (feed ×
  /// override, mm/s) and the hold (no motion). True when the block is done.
  bool step(double dt_s, double gap_voltage_v, double servo_ref_v, std::int64_t n_short,
            std::int64_t n_pulses, double cap_mm_s, bool hold) noexcept;
  /// Forgets the history (a non-cut block, a safe state, the job's end).
  void reset() noexcept;

  [[nodiscard]] double ref_x() const noexcept { return ref_x_; }
  [[nodiscard]] double ref_y() const noexcept { return ref_y_; }
  [[nodiscard]] double v_x() const noexcept { return vx_; }
  [[nodiscard]] double v_y() const noexcept { return vy_; }

 private:
  void point_at(double s, double& x, double& y, double& tx, double& ty) const noexcept;
  void push_history(double x, double y) noexcept;
  /// The point `back` behind the frontier along the history (and the direction forward there).
  void history_point(double back, double& x, double& y, double& tx, double& ty) const noexcept;
  [[nodiscard]] double history_mm() const noexcept;

  // The block: a line (x0, y0) → (x1, y1) or an arc about (cx, cy).
  bool arc_{false}, cw_{false};
  double x0_{0.0}, y0_{0.0}, x1_{0.0}, y1_{0.0}, cx_{0.0}, cy_{0.0};
  double r_{0.0}, a0_{0.0}, sweep_{0.0};  // arc: radius, start angle, signed sweep (rad)
  double length_{0.0};
  double s_{0.0};        // the frontier along the block
  double back_{0.0};     // how far behind the frontier the wire is
  double retreat_{0.0};  // a short's back-up still to make
  double v_{0.0};        // path speed now (negative: backing up)
  double u_f_{0.0};
  bool u_init_{false};
  double since_push_{0.0};  // path length since the newest history point
  std::array<double, kHistoryPoints> hx_{}, hy_{};
  std::size_t head_{0}, count_{0};
  double ref_x_{0.0}, ref_y_{0.0}, vx_{0.0}, vy_{0.0};
};

}  // namespace edm::programs
