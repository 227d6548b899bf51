#pragma once
// JumpCycle: the periodic electrode jump of die sinking (the flushing jump). Every `period` the
// electrode is lifted at up_speed_mm_s for up_time and brought back at down_speed_mm_s for
// down_time (so it returns short of where it was when up_speed·up_time > down_speed·down_time),
// then the gap servo's command passes through again until the next jump:
//
//   n = cycles since the block was enabled (activate(), `enable` rising, or the end of a safe
//       state); P, U, D = period, up_time, down_time in task cycles
//   a jump starts at n = P, 2P, 3P, …  (the first after one whole period of servo)
//   phase j = cycles since the jump started:
//     j < U        vz_out = +up_speed_mm_s                       jumping = true
//     j < U + D    vz_out = −down_speed_mm_s                     jumping = true
//     otherwise    vz_out = vz_in_mm_s (the servo)              jumping = false
//   cycle_start = true in the first cycle of each jump (seed 002's ILC cycle edge: one jump
//   cycle = one ILC cycle); jumps counts them;
//   z_hold_mm = z_mm, held at its value of the jump's first cycle while jumping (what the
//   electrode position was before the jump: the ILC warm start's `track` must not learn the jump).
//   settling = jumping, or within S = settle_time cycles after the jump (the approach, while the
//   servo closes the gap again: its open pulses are not the machining's); S = 0: = jumping.
//   servo_part = not settling (wire a controller's `enable` to it).
//
// Wire io.vz_cmd from vz_out_mm_s. Samples taken while `jumping` are not the servo's: hold a
// controller's measurement through a Select (g = jumping); samples taken while `settling` are
// not the machining's either: hold the STR's `enable` with it (docs/benchmarks.md, B5). `enable`
// false starts no jump and resets n (a running jump finishes). A safe state aborts a running jump
// (vz_out = 0 in enter_safe_state); update() in a safe state starts no jump and passes vz_in.
// A non-finite vz_in outside a jump → vz_out = 0, kFault (a jump runs on: it does not read
// vz_in); a non-finite z_mm → z_hold_mm held, kFault.
// RT-safe: update(), enter_safe_state(). Not thread-safe: the owning task calls every member
// except the pins (see pin.hpp).

#include <chrono>
#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct JumpCycleParams {
  rt::Duration period{std::chrono::milliseconds(1500)};   // > up_time + down_time
  rt::Duration up_time{std::chrono::milliseconds(40)};    // > 0
  rt::Duration down_time{std::chrono::milliseconds(50)};  // > 0
  double up_speed_mm_s{30.0};                             // [mm/s] > 0
  double down_speed_mm_s{30.0};                           // [mm/s] > 0
  rt::Duration settle_time{};  // >= 0; `settling` stays true this long after the jump

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): die-sinking jumps every 0.1-10 s (PM §6.5: 1.5 s), so a period up to
    // 10 min and up, down and settle times up to 1 min; speeds as any axis (param_ranges.hpp).
    v.param("period", period,
            {"s", "time from one jump's start to the next, > up + down + settle time",
             rt::open_closed(0.0, 600.0)});
    v.param("up_time", up_time, {"s", "time the electrode rises", rt::open_closed(0.0, 60.0)});
    v.param("down_time", down_time, {"s", "time it comes back down", rt::open_closed(0.0, 60.0)});
    v.param("up_speed_mm_s", up_speed_mm_s, {"mm/s", "rising speed", ranges::kSpeedMmS});
    v.param("down_speed_mm_s", down_speed_mm_s, {"mm/s", "lowering speed", ranges::kSpeedMmS});
    v.param("settle_time", settle_time,
            {"s", "`settling` stays true this long after the jump (the approach)",
             rt::closed(0.0, 60.0)});
  }
  /// Cross-field rule: period > up_time + down_time + settle_time.
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class JumpCycle final : public rt::BlockWithParams<JumpCycleParams> {
 public:
  /// Non-RT. Converts the times to task cycles (at least 1 each); needs a task period > 0.
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. n = 0, no jump, vz_out = vz_in.
  void activate() noexcept override;
  /// RT-safe. kOk, or kFault (non-finite vz_in outside a jump, or non-finite z_mm).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;
  /// RT-safe. Aborts a running jump: vz_out = 0, jumping = false, n = 0.
  void enter_safe_state(const rt::SafeStateRequest& request) noexcept override;

 protected:
  void params_changed() noexcept override;

 private:
  void reset() noexcept;

  rt::Input<double> vz_in_{pins_, "vz_in_mm_s", "mm/s"};
  rt::Input<double> z_mm_{pins_, "z_mm", "mm"};
  rt::Input<bool> enable_{pins_, "enable", "", true};
  rt::Output<double> vz_out_{pins_, "vz_out_mm_s", "mm/s"};
  rt::Output<double> z_hold_{pins_, "z_hold_mm", "mm"};
  rt::Output<bool> jumping_{pins_, "jumping"};
  rt::Output<bool> settling_{pins_, "settling"};
  rt::Output<bool> servo_part_{pins_, "servo_part"};
  rt::Output<bool> cycle_start_{pins_, "cycle_start"};
  rt::Output<std::int64_t> jumps_{pins_, "jumps"};
  rt::Duration task_period_{};
  std::int64_t period_n_{1}, up_n_{1}, down_n_{1}, settle_n_{0};
  std::int64_t settle_left_{0};  // cycles of `settling` left after the last jump
  std::int64_t n_{0};            // cycles since enabled
  std::int64_t phase_{-1};       // cycles since the running jump started, −1: no jump
  bool was_enabled_{true};
  bool was_safe_{false};
};

}  // namespace edm::blocks
