#pragma once
// WallFinish: the hole-wall finishing cycle of seed 004 as a C++ PROGRAM type: after drilling
// with negative polarity, switch to positive polarity and orbit the electrode in XY about the hole
// centre with a radius that grows once per revolution by Δr = kr·Tdm (eq. 20–21).
//
// Children (their pins and parameters are variables program.<instance>.<child>.<name>):
//   pol    PolaritySwitch  switches the polarity only with the generator off (settle each side)
//   td     TdDetector      mean ignition delay from the pulse counters
//   orbit  OrbitExpander   orbit offset r: r0 = start_offset_mm, grows by clamp(kr·Tdm) per
//                          revolution up to final_offset_mm (exactly)
//   arc    CircularInterpolator  the orbit's path (eq. 14–19): full circles of radius R_b (the
//                          final offset) about the hole centre at the orbit feed fr
//   px/py  PositionLoop    X/Y position loops: (x_ref, v_ff, x) → v_cmd
//
// Sequence (output `state`):
//   0 IDLE      generator off, v = 0. A rising edge of `start` latches the hole centre
//               (x0, y0) = (x_mm, y_mm), start_offset_mm and final_offset_mm → POLARITY.
//   1 POLARITY  generator off; pol.request_positive = true; when pol reports positive polarity and
//               no longer switching → ORBIT (orbit child started with r0 = start_offset_mm).
//   2 ORBIT     generator on (through pol). The circular interpolator (arc) runs full circles
//               of radius R_b = the final offset about the centre at the orbit feed fr (the
//               feed_mm_min input when > 0, e.g. G160's F, else the parameter); seed 004's
//               Fig. 1 adds the orbit compensation along the radial direction u = (cos θ, sin θ),
//               θ = arc.angle_rad:
//                 x_ref = arc.rx + (ρ − R_b)·cos θ,  y_ref = arc.ry + (ρ − R_b)·sin θ
//               (= centre + ρ·u). ρ slews toward the orbit child's radius_mm at
//               ≤ radial_speed_mm_s (the entry from the centre, and each per-revolution step).
//               One revolution = arc.swept_rad crossing a multiple of 2π; it pulses
//               orbit.rev_pulse. Td samples are collected only while
//               ρ has reached the radius. When the orbit child is done (radius = final), the
//               electrode makes spark_out_revs more revolutions at the final radius → BACK.
//   3 BACK      generator off, ρ slews to 0; once |(x, y) − (x0, y0)| ≤ centre_tol_mm → DONE.
//   4 DONE      generator off, v = 0, done = true; a new rising edge of `start` restarts.
// The velocity feed-forward of the loops is the derivative of the reference.
//
// Safe state (FAULT / ESTOP): generator off and v = 0 at once (the loops' own safe state); a
// running cycle ends in IDLE (done false). `start` is ignored while in a safe state.
//
// The children's parameters are set in YAML under this block's params (`orbit: {kr: 1e-4}`,
// `px: {kv: 20}`, `pol: {settle: 20ms}`, `td: {window: 8}`). This program's defaults for them:
// orbit.kr = 1e-4 mm/µs and orbit.dr_max_mm = 0.01 mm (eq. 21 live: Td ≤ the open threshold of
// 100 µs keeps kr·Tdm under the limit, so the step is kr·Tdm every revolution; before issue 20 a
// 0.002 mm limit clamped every step), orbit.samples_per_rev = 0 (revolutions come from the
// orbit phase: another value is refused), pol.initial_positive = false, px/py.v_max_mm_s = 5.
// Connected by member in bind_self(): td's counters and px/py's positions follow this block's
// inputs; orbit.td_us/valid ← td; the sequence drives the rest (Input::drive: pol's requests,
// orbit's start/enable/rev_pulse/r0/final radius, arc's load point and feed, the loops'
// references, feed-forwards and enables, the retract's contour), readable as those children's
// inputs (`finish.px.x_ref_mm`, …).
// Short circuits in ORBIT: td pools shorts as Td ≈ 0, so Tdm and the growth Δr = kr·Tdm shrink
// by themselves. While the window reads short (gap_short: td.short_ratio ≥ short_ratio_limit)
// the phase and the radius wait (no advance toward the wall); a retract child (ShortRetract on
// the commanded reference px/py.x_ref_mm) backs the electrode along the contour already
// travelled and walks it forward again, the loops following its setpoint; then the orbit
// continues from where it stopped. Too many retracts without progress: alarm 150 (fault); the
// safe state stops the orbit. cycle_short (td.cycle_short_ratio ≥ short_ratio_limit: this
// cycle's own pulses, issue 31) makes the phase and the radius wait in that same cycle too, and
// while either reads short (short_now = gap_short || cycle_short, which the retract child
// counts) the X/Y command has no component toward the wall: its part along the electrode's
// radius from the hole centre, outward, is removed.
//
// RT-safety: update() and enter_safe_state() are RT-safe (noexcept, no allocation, no locks).
// Not thread-safe: the owning task calls every member except the pins (see pin.hpp).

#include <cstdint>
#include <string>
#include <vector>

#include "edm/blocks/circular_interpolator.hpp"
#include "edm/blocks/orbit_expander.hpp"
#include "edm/blocks/polarity_switch.hpp"
#include "edm/blocks/position_loop.hpp"
#include "edm/blocks/short_retract.hpp"
#include "edm/blocks/td_detector.hpp"
#include "edm/programs/machining_cycle.hpp"
#include "edm/programs/pulse_inputs.hpp"
#include "edm/programs/short_guard.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/composite_block.hpp"

namespace edm::programs {

struct WallFinishParams {
  double feed_default_mm_min{30.0};  // [mm/min] orbit feed fr along R_b (feed_mm_min input ≤ 0)
  double radial_speed_mm_s{0.05};    // [mm/s] slew of the reference radius
  std::int64_t spark_out_revs{4};    // revolutions at the final radius before BACK
  double centre_tol_mm{0.002};       // [mm] BACK ends within this of the centre
  // ORBIT without a single ignited or shorted pulse for this long (outside spark-out) is a fault:
  // no work, no generator, a wrong offset. 0 s: off.
  rt::Duration no_spark_timeout{std::chrono::seconds(30)};
  // Short circuits in the orbit (as DeepHoleDrill's): short_ratio_limit, short_retracts_max,
  // short_retracts_window.
  ShortLimits shorts{};

  void visit(rt::ParamVisitor& v);
};

class WallFinish final : public rt::BlockWithParams<WallFinishParams, rt::CompositeBlock>,
                         public MachiningCycle {
 public:
  enum class State : std::int64_t { kIdle = 0, kPolarity = 1, kOrbit = 2, kBack = 3, kDone = 4 };

  WallFinish();
  /// The job was stopped by the operator: the orbit stops as in the safe state (IDLE, done
  /// false). RT-safe.
  void abort() noexcept override { safe_state_self(rt::SafeStateRequest{}); }
  /// MachiningCycle: from the start to DONE or IDLE it commands X and Y.
  [[nodiscard]] bool running() const noexcept override {
    return state_value_ != State::kIdle && state_value_ != State::kDone;
  }
  [[nodiscard]] AxisClaim axes() const noexcept override {
    return AxisClaim::xy(vx_cmd_mm_s.get(), vy_cmd_mm_s.get());
  }
  [[nodiscard]] bool generator_on() const noexcept override { return gen_on.get(); }

  // Pins, listed in declaration order.
  PulseInputs pulses{pins_};  // td_sum_ns, td_count, n_open, n_short
  rt::Input<double> x_mm{pins_, "x_mm", "mm"};
  rt::Input<double> y_mm{pins_, "y_mm", "mm"};
  rt::Input<bool> start{pins_, "start"};
  rt::Input<double> start_offset_mm{pins_, "start_offset_mm", "mm"};
  rt::Input<double> final_offset_mm{pins_, "final_offset_mm", "mm"};
  rt::Input<bool> hold{pins_, "hold"};                               // feed hold in the orbit
  rt::Input<double> feed_mm_min{pins_, "feed_mm_min", "mm/min"};     // > 0: the orbit feed fr
  rt::Input<double> feed_override{pins_, "feed_override", "", 1.0};  // scales fr, 0 … 1.5
  rt::Output<bool> no_spark{pins_, "no_spark"};  // the no-spark timeout tripped (a fault)
  rt::Output<double> vx_cmd_mm_s{pins_, "vx_cmd_mm_s", "mm/s"};
  rt::Output<double> vy_cmd_mm_s{pins_, "vy_cmd_mm_s", "mm/s"};
  rt::Output<bool> gen_on{pins_, "gen_on"};
  rt::Output<bool> polarity_positive{pins_, "polarity_positive"};
  rt::Output<std::int64_t> state{pins_, "state"};
  rt::Output<double> offset_mm{pins_, "offset_mm", "mm"};
  rt::Output<double> rho_mm{pins_, "rho_mm", "mm"};  // reference radius actually commanded
  rt::Output<std::int64_t> revolutions{pins_, "revolutions"};
  rt::Output<bool> done{pins_, "done"};
  // gap_short, short_retracts (retracts in this orbit), cycle_short, short_now.
  ShortPins short_pins{pins_};

 protected:
  std::vector<rt::ParamError> configure_self(const rt::BlockSetup& setup) override;
  void bind_self() override;
  void activate_self() noexcept override;
  void safe_state_self(const rt::SafeStateRequest& request) noexcept override;
  /// RT-safe. kOk, or the worst status of the children stepped this cycle.
  rt::BlockStatus update_self(const rt::CycleContext& ctx) noexcept override;

 private:
  void set_state(State s) noexcept;
  void stop_outputs() noexcept;
  /// The loops' and the retract's reference point. RT-safe.
  void set_reference(double x, double y) noexcept;
  void enable_loops(bool on) noexcept;
  /// One ORBIT cycle of the short handling; true while the retract owns the reference.
  bool handle_short(const rt::CycleContext& ctx, rt::BlockStatus& status) noexcept;

  blocks::PolaritySwitch& pol_;
  blocks::TdDetector& td_;
  blocks::OrbitExpander& orbit_;
  blocks::CircularInterpolator& arc_;
  blocks::PositionLoop& px_;
  blocks::PositionLoop& py_;
  blocks::ShortRetract& retract_;
  rt::Machine* machine_{nullptr};
  std::string source_;  // this block's instance name, for alarm 150
  ShortGuard guard_;

  State state_value_{State::kIdle};
  bool prev_start_{false};
  double dark_s_{0.0};  // time in ORBIT since the last ignited or shorted pulse
  double x0_{0.0}, y0_{0.0};
  double x_ref_{0.0}, y_ref_{0.0};  // the reference point last given to the loops
  double rho_{0.0};                 // [mm] reference radius
  double theta_{0.0};               // [rad] the arc's polar angle (radial direction)
  double r_base_{0.0};              // [mm] R_b, the arc's radius
  std::int64_t arc_turns_{0};       // whole turns the arc has swept
  std::int64_t revs_{0};
  std::int64_t spark_out_left_{0};
  bool spark_out_{false};
};

}  // namespace edm::programs
