#pragma once
// PositionLoop: one axis position loop (X, Y or Z), P or PI with velocity feed-forward.
//
//   e      = x_ref − x                                                    [mm]
//   I     ← I + e·dt             (held while the output is saturated and e pushes further in)
//   v_cmd  = clamp(kv·e + ki·I + kff·v_ff, −v_max, +v_max)                [mm/s]
//
// Anti-windup by conditional integration: when the unclamped command exceeds v_max and the error
// has the same sign, the integral keeps its previous value, so it never grows while saturated.
// Following error: while enabled, |e| > f_err_max latches following_error_fault; while latched
// v_cmd = 0, the integral is cleared and update() returns kFault (the runtime's block-fault alarm).
// reset = true clears the latch (a following error still beyond the limit latches again at once).
// in_position = |e| ≤ in_pos_tol for the last in_pos_cycles consecutive cycles.
// enable = false: v_cmd = 0, the integral is cleared, no following-error check (the axis is not
// under position control), error_mm and in_position are still computed.
// Non-finite input: v_cmd = 0 (a broken encoder or reference must not keep the axis moving),
// error_mm held, in_position false, kFault; the integral is not touched.
// RT-safe: update(), params_changed(). Not thread-safe: the owning task calls every member except
// the pins (see pin.hpp).

#include <cstdint>
#include <vector>

#include "edm/blocks/param_ranges.hpp"
#include "edm/runtime/block.hpp"

namespace edm::blocks {

struct PositionLoopParams {
  double kv{20.0};                // [1/s] position gain (velocity per mm of error)
  double ki{0.0};                 // [1/s²] integral gain, 0 = P loop
  double kff{1.0};                // [-] velocity feed-forward weight, 0..1.5
  double v_max_mm_s{50.0};        // [mm/s] > 0
  double f_err_max_mm{1.0};       // [mm] > 0, following-error limit
  double in_pos_tol_mm{0.002};    // [mm] ≥ 0
  std::int64_t in_pos_cycles{5};  // [cycles] ≥ 1

  void visit(rt::ParamVisitor& v) {
    // Ranges (issue 31): kv as any position loop (param_ranges.hpp), ki up to 1e6 1/s² (kv² at
    // kv = 1000), a following-error limit up to 1 m (the sinking ILC bench uses 100 mm).
    v.param("kv", kv,
            {"1/s", "position gain: v_cmd per mm of following error", ranges::kLoopGainPerS});
    v.param("ki", ki, {"1/s^2", "integral gain (0 = P loop)", rt::closed(0.0, 1.0e6)});
    v.param("kff", kff, {"", "velocity feed-forward weight", rt::closed(0.0, 1.5)});
    v.param("v_max_mm_s", v_max_mm_s, {"mm/s", "velocity command limit", ranges::kSpeedMmS});
    v.param("f_err_max_mm", f_err_max_mm,
            {"mm", "following-error limit", rt::open_closed(0.0, 1000.0)});
    v.param("in_pos_tol_mm", in_pos_tol_mm,
            {"mm", "in-position window, |e| <= tol", ranges::kToleranceMm});
    v.param("in_pos_cycles", in_pos_cycles,
            {"cycles", "cycles |e| must stay in the window before in_position",
             rt::closed(1.0, 1.0e9)});
  }
};

class PositionLoop final : public rt::BlockWithParams<PositionLoopParams> {
 public:
  /// Non-RT. Needs a task period > 0.
  std::vector<rt::ParamError> configure(const rt::BlockSetup& setup) override;
  /// Non-RT. Clears the integral, the in-position count and the fault latch; v_cmd = 0.
  void activate() noexcept override;
  /// RT-safe. kOk, kSaturated (velocity limit) or kFault (following error latched, non-finite
  /// input).
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;
  /// RT-safe. Stops the axis: v_cmd = 0 and the integral is cleared.
  void enter_safe_state(const rt::SafeStateRequest& request) noexcept override;

 public:
  // Pins, listed under their names in declaration order: a C++ PROGRAM connects them by member.
  rt::Input<double> x_ref_mm{pins_, "x_ref_mm", "mm"};
  rt::Input<double> v_ff_mm_s{pins_, "v_ff_mm_s", "mm/s"};
  rt::Input<double> x_mm{pins_, "x_mm", "mm"};
  rt::Input<bool> enable{pins_, "enable", "", true};
  rt::Input<bool> reset{pins_, "reset"};
  rt::Output<double> v_cmd_mm_s{pins_, "v_cmd_mm_s", "mm/s"};
  rt::Output<double> error_mm{pins_, "error_mm", "mm"};
  rt::Output<bool> in_position{pins_, "in_position"};
  rt::Output<bool> following_error_fault{pins_, "following_error_fault"};
  rt::Output<bool> saturated{pins_, "saturated"};

 private:
  double dt_s_{0.0};
  double integral_mm_s_{0.0};  // ∫e dt [mm·s]
  std::int64_t in_pos_count_{0};
  bool fault_latched_{false};
};

}  // namespace edm::blocks
