#pragma once
// ShortRetract: on a sustained short circuit, retract along the recorded path, walk forward again
// and hand control back with a bounded re-acceleration (DESIGN §11).
//
// Path history: while the block is not active, the commanded position (x_mm, y_mm, z_mm) of each
// cycle is appended to a ring of history_capacity points (allocated in configure(); the oldest
// point is dropped when full) once it is at least min_spacing_mm from the last point, with its
// arc-length coordinate s (s of the new point = s of the last point + distance). A point that
// moves back over the last segment (it lies behind the head and closer to the point before it)
// removes the head first, so a gap servo that backs off and re-advances leaves the net path, not
// its oscillations.
//
// States:
//   IDLE     active = false, setpoints = inputs, v_scale = 1. short_detected for short_cycles
//            consecutive cycles → tries += 1, RETRACT from the head (the current point is
//            appended first, so the head is where the controller stands).
//   RETRACT  active = true: s ← max(s − retract_speed·dt, s_head − retract_distance, s_oldest);
//            the setpoints are the path at s (linear between points). At the target → RESUME.
//   RESUME   active = true: s ← min(s + resume_speed·dt, s_head); at s_head (the setpoints equal
//            the head exactly) → RAMP. A sustained short here retracts again from the current s.
//   RAMP     active = false, setpoints = inputs, v_scale = k / ramp_cycles in the k-th cycle
//            after hand-back (ramp_cycles = floor(resume_ramp_ms / dt)), so the controller is at
//            full feed within resume_ramp_ms; then IDLE. Recording and short detection as IDLE.
//   HOLD     active = true, setpoints held at the retracted point, alarm and hold true.
// Tries: reset to 0 once the head has advanced progress_mm along the path beyond the head at the
// last retract. A sustained short while tries == max_tries raises alarm and hold instead: the
// block retracts once more and then stays in HOLD; update() returns kFault while alarm is set.
// retracts counts every retract started since activate() (tries is reset by progress; this is
// not), so a consumer can count retracts over a time window.
// reset = true clears alarm, hold and tries (HOLD → RESUME: walk back to the head).
// enable = false: IDLE, history and short count cleared (alarm stays latched until reset).
// The controller must hold its commanded position while active is true (the inputs are not read
// then) so that hand-back at the head is bumpless.
// Non-finite position input while recording: nothing recorded, outputs held, kFault.
// Cost: O(1) per cycle plus the path segments crossed in that cycle (≈ speed·dt / spacing) and
// the points removed by a back-off (each removed point was appended once).
// RT-safe: update(). Not thread-safe: the owning task calls every member except the pins.

#include <array>
#include <cstdint>
#include <vector>

#include "edm/blocks/window_ring.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct ShortRetractParams {
  static constexpr std::int64_t kMaxHistory = 1 << 20;

  std::int64_t history_capacity{4096};  // [points] 2..kMaxHistory, load time only
  double min_spacing_mm{0.001};         // [mm] ≥ 0
  std::int64_t short_cycles{10};        // [cycles] ≥ 1
  double retract_distance_mm{0.5};      // [mm] > 0, along the path
  double retract_speed_mm_s{5.0};       // [mm/s] > 0
  double resume_speed_mm_s{2.0};        // [mm/s] > 0
  double resume_ramp_ms{200.0};         // [ms] 0..60000
  std::int64_t max_tries{3};            // retracts without progress before alarm, ≥ 0
  double progress_mm{0.05};             // [mm] ≥ 0, path advance that resets tries

  void visit(rt::ParamVisitor& v) {
    v.param("history_capacity", history_capacity,
            rt::load_time({"points", "path points kept (it sizes the path ring)",
                           rt::closed(2.0, static_cast<double>(kMaxHistory))}));
    v.param("min_spacing_mm", min_spacing_mm,
            {"mm", "least distance between recorded points", rt::closed(0.0, 1.0e3)});
    v.param("short_cycles", short_cycles,
            {"cycles", "consecutive short cycles that start a retract", rt::closed(1.0, 1.0e9)});
    v.param("retract_distance_mm", retract_distance_mm,
            {"mm", "retract length along the path", rt::closed(1.0e-9, 1.0e4)});
    v.param("retract_speed_mm_s", retract_speed_mm_s,
            {"mm/s", "path speed while retracting", rt::closed(1.0e-9, 1.0e4)});
    v.param("resume_speed_mm_s", resume_speed_mm_s,
            {"mm/s", "path speed walking forward again", rt::closed(1.0e-9, 1.0e4)});
    v.param("resume_ramp_ms", resume_ramp_ms,
            {"ms", "time to ramp v_scale 0 -> 1 after hand-back", rt::closed(0.0, 60000.0)});
    v.param("max_tries", max_tries,
            {"", "retracts without progress before alarm + hold", rt::closed(0.0, 1.0e6)});
    v.param("progress_mm", progress_mm,
            {"mm", "path advance past the last short that resets tries", rt::closed(0.0, 1.0e4)});
  }
};

class ShortRetract final : public rt::BlockWithParams<ShortRetractParams> {
 public:
  enum class State : std::uint8_t { kIdle, kRetract, kResume, kRamp, kHold };
  /// Non-RT. Needs a task period > 0. Allocates the path ring (history_capacity points).
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. Empties the history; IDLE, tries 0, alarm cleared.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault while alarm is set or on a non-finite position input.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;
  /// The current state. For tests and diagnostics; not synchronised.
  [[nodiscard]] State state() const noexcept { return state_; }
  /// Points in the history. For tests and diagnostics; not synchronised.
  [[nodiscard]] std::size_t history_size() const noexcept { return history_.size(); }

 protected:
  /// RT-safe. Recomputes the ramp length after a runtime write.
  void params_changed() noexcept override;

 private:
  struct PathPoint {
    double x{0.0}, y{0.0}, z{0.0};
    double s{0.0};  // arc-length coordinate [mm]
  };

  [[nodiscard]] const PathPoint& at(std::size_t i) const noexcept { return history_[i]; }
  [[nodiscard]] const PathPoint& head() const noexcept { return at(history_.size() - 1); }
  void record(double x, double y, double z, bool force) noexcept;
  void start_retract(bool from_head) noexcept;
  void set_point_at(double s) noexcept;
  void compute_ramp() noexcept;

 public:
  // Pins, listed under their names in declaration order: a C++ PROGRAM connects them by member.
  rt::Input<double> x_mm{pins_, "x_mm", "mm"};
  rt::Input<double> y_mm{pins_, "y_mm", "mm"};
  rt::Input<double> z_mm{pins_, "z_mm", "mm"};
  rt::Input<bool> short_detected{pins_, "short_detected"};
  rt::Input<bool> enable{pins_, "enable", "", true};
  rt::Input<bool> reset{pins_, "reset"};
  rt::Output<bool> active{pins_, "active"};
  rt::Output<double> x_sp_mm{pins_, "x_sp_mm", "mm"};
  rt::Output<double> y_sp_mm{pins_, "y_sp_mm", "mm"};
  rt::Output<double> z_sp_mm{pins_, "z_sp_mm", "mm"};
  rt::Output<double> v_scale{pins_, "v_scale", "", 1.0};
  rt::Output<std::int64_t> tries{pins_, "tries"};
  rt::Output<std::int64_t> retracts{
      pins_, "retracts"};  // retracts started since activate() (progress never resets)
  rt::Output<bool> alarm{pins_, "alarm"};
  rt::Output<bool> hold{pins_, "hold"};

 private:
  WindowRing<PathPoint> history_;  // allocated in configure(); at(0) is the oldest point
  double dt_s_{0.0};
  State state_{State::kIdle};
  double pos_s_{0.0};           // arc coordinate of the setpoint while active
  double target_s_{0.0};        // where the retract stops
  std::size_t seg_{0};          // at(seg_).s ≤ pos_s_ ≤ at(seg_ + 1).s
  std::array<double, 3> sp_{};  // setpoints x, y, z [mm]
  std::int64_t short_count_{0};
  std::int64_t tries_{0};
  double s_at_short_{0.0};  // head s at the last retract
  bool alarm_{false};
  bool final_{false};  // this retract ends in HOLD
  std::int64_t ramp_k_{0};
  std::int64_t ramp_cycles_{0};
};

}  // namespace edm::blocks
