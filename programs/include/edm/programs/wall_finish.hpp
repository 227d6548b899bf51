#pragma once
// WallFinish: the hole-wall finishing cycle of seed 004 as a C++ PROGRAM type: after drilling
// with negative polarity, switch to positive polarity and orbit the electrode in XY about the hole
// centre with a radius that grows once per revolution by Δr = kr·Tdm (eq. 20–21).
//
// Children (variables program.<instance>.<child>.<pin>):
//   pol    PolaritySwitch  switches the polarity only with the generator off (settle each side)
//   td     TdDetector      mean ignition delay from the pulse counters
//   orbit  OrbitExpander   orbit offset r: r0 = start_offset_mm, grows by clamp(kr·Tdm) per
//                          revolution up to final_offset_mm (exactly)
//   px/py  PositionLoop    X/Y position loops: (x_ref, v_ff, x) → v_cmd
// The circle is computed here (no CircularInterpolator: the radius changes every revolution).
//
// Sequence (output `state`):
//   0 IDLE      generator off, v = 0. A rising edge of `start` latches the hole centre
//               (x0, y0) = (x_mm, y_mm), start_offset_mm and final_offset_mm → POLARITY.
//   1 POLARITY  generator off; pol.request_positive = true; when pol reports positive polarity and
//               no longer switching → ORBIT (orbit child started with r0 = start_offset_mm).
//   2 ORBIT     generator on (through pol). Reference point:
//                 x_ref = x0 + ρ·cos θ,  y_ref = y0 + ρ·sin θ,  θ += 2π·dt/orbit_period_s
//               ρ slews toward the orbit child's radius_mm at ≤ radial_speed_mm_s (the entry
//               from the centre, and each per-revolution step). One revolution = θ crossing a
//               multiple of 2π; it pulses orbit.rev_pulse. Td samples are collected only while
//               ρ has reached the radius. When the orbit child is done (radius = final), the
//               electrode makes spark_out_revs more revolutions at the final radius → BACK.
//   3 BACK      generator off, ρ slews to 0; once |(x, y) − (x0, y0)| ≤ centre_tol_mm → DONE.
//   4 DONE      generator off, v = 0, done = true; a new rising edge of `start` restarts.
// The velocity feed-forward of the loops is the derivative of the reference.
//
// Safe state (FAULT / ESTOP): generator off and v = 0 at once (the loops' own safe state); a
// running cycle ends in IDLE (done false). `start` is ignored while in a safe state.
//
// Parameters kr, dr_max_mm (→ orbit), kv, v_max_mm_s, f_err_max_mm (→ px, py), settle (→ pol) and
// td_window (→ td, load time only) are copied into the children at configure time; kr, dr_max_mm,
// kv are copied again on a runtime write.
//
// RT-safety: update() and enter_safe_state() are RT-safe (noexcept, no allocation, no locks).
// Not thread-safe: the owning task calls every member except the pins (see pin.hpp).

#include <cstdint>
#include <vector>

#include "edm/blocks/orbit_expander.hpp"
#include "edm/blocks/polarity_switch.hpp"
#include "edm/blocks/position_loop.hpp"
#include "edm/blocks/td_detector.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/composite_block.hpp"

namespace edm::programs {

struct WallFinishParams {
  double orbit_period_s{0.5};                   // [s] > 0, time of one revolution
  double radial_speed_mm_s{0.05};               // [mm/s] > 0, slew of the reference radius
  std::int64_t spark_out_revs{2};               // ≥ 0 revolutions at the final radius before BACK
  double centre_tol_mm{0.002};                  // [mm] > 0, BACK ends within this of the centre
  double kr{blocks::OrbitExpanderParams{}.kr};  // [mm/µs] ≥ 0 → orbit.kr
  double dr_max_mm{0.005};                      // [mm] ≥ 0 → orbit.dr_max_mm
  double kv{blocks::PositionLoopParams{}.kv};   // [1/s] ≥ 0 → px, py
  double v_max_mm_s{5.0};                       // [mm/s] > 0 → px, py
  double f_err_max_mm{blocks::PositionLoopParams{}.f_err_max_mm};  // [mm] > 0 → px, py
  rt::Duration settle{blocks::PolaritySwitchParams{}.settle};      // > 0 → pol (load time only)
  std::int64_t td_window{8};  // cycles, → td.window (load time only)
  // ORBIT without a single ignited or shorted pulse for this long (outside spark-out) is a fault:
  // no work, no generator, a wrong offset. 0 s: off.
  rt::Duration no_spark_timeout{std::chrono::seconds(30)};  // ≥ 0

  void visit(rt::ParamVisitor& v);
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class WallFinish final : public rt::BlockWithParams<WallFinishParams, rt::CompositeBlock> {
 public:
  enum class State : std::int64_t { kIdle = 0, kPolarity = 1, kOrbit = 2, kBack = 3, kDone = 4 };

  WallFinish();

  /// RT-safe. kOk, or the worst status of the children stepped this cycle.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;
  /// Non-RT. Refuses settle and td_window (load time only).
  std::vector<rt::ParamError> stage_param(std::size_t index, const rt::ParamValue& v) override;

 protected:
  void visit_own_pins(rt::PinVisitor& v) override;
  std::vector<rt::ParamError> configure_self(const rt::BlockSetup& setup) override;
  void activate_self() noexcept override;
  void safe_state_self(const rt::SafeStateRequest& request) noexcept override;
  void params_changed() noexcept override;

 private:
  void set_state(State s) noexcept;
  void stop_outputs() noexcept;

  blocks::PolaritySwitch& pol_;
  blocks::TdDetector& td_;
  blocks::OrbitExpander& orbit_;
  blocks::PositionLoop& px_;
  blocks::PositionLoop& py_;

  // Own pins.
  rt::Input<std::int64_t> td_sum_ns_, td_count_, n_open_, n_short_;
  rt::Input<double> x_mm_, y_mm_;
  rt::Input<bool> start_;
  rt::Input<bool> hold_;       // feed hold in the orbit
  rt::Output<bool> no_spark_;  // the no-spark timeout tripped (a fault)
  double dark_s_{0.0};         // time in ORBIT since the last ignited or shorted pulse
  rt::Input<double> start_offset_mm_;
  rt::Input<double> final_offset_mm_;
  rt::Output<double> vx_cmd_mm_s_, vy_cmd_mm_s_;
  rt::Output<bool> gen_on_;
  rt::Output<bool> polarity_positive_;
  rt::Output<std::int64_t> state_;
  rt::Output<double> offset_mm_;
  rt::Output<double> rho_mm_;  // reference radius actually commanded
  rt::Output<std::int64_t> revolutions_;
  rt::Output<bool> done_;

  // Private cells the children's inputs are wired to.
  rt::Output<std::int64_t> c_td_sum_ns_, c_td_count_, c_n_open_, c_n_short_;
  rt::Output<bool> c_pol_req_, c_gen_req_;
  rt::Output<bool> c_orbit_start_, c_orbit_enable_, c_rev_pulse_;
  rt::Output<double> c_r0_, c_final_;
  rt::Output<double> c_xref_, c_yref_, c_vffx_, c_vffy_, c_x_, c_y_;
  rt::Output<bool> c_loop_enable_;
  // Children's outputs read by the sequence.
  const rt::Output<bool>* pol_positive_{nullptr};
  const rt::Output<bool>* pol_gen_{nullptr};
  const rt::Output<bool>* pol_switching_{nullptr};
  const rt::Output<double>* orbit_radius_{nullptr};
  const rt::Output<bool>* orbit_done_{nullptr};
  const rt::Output<std::int64_t>* orbit_revs_{nullptr};
  const rt::Output<double>* px_v_{nullptr};
  const rt::Output<double>* py_v_{nullptr};

  State state_value_{State::kIdle};
  bool prev_start_{false};
  double x0_{0.0}, y0_{0.0};
  double rho_{0.0};    // [mm] reference radius
  double theta_{0.0};  // [rad] in [0, 2π)
  std::int64_t revs_{0};
  std::int64_t spark_out_left_{0};
  bool spark_out_{false};
};

}  // namespace edm::programs
