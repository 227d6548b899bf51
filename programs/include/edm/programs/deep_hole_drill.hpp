#pragma once
// DeepHoleDrill: the deep-hole drilling cycle of seed 004 as a C++ PROGRAM type.
//
// Children (variables program.<instance>.<child>.<pin>):
//   td    TdDetector       mean ignition delay over `td_window` cycles from the pulse counters
//   gap   GapControllerP   Vz = Kg·(Tdr − Td)                       (eq. 1)
//   wear  WearCompensator  vz_out = vz_in − Vd, Vd = θ·(A_hole/A_e)·|vz_in|, wear_mm = ∫Vd dt
//                          (eq. 8)
// Wired in C++ at configure time: the composite's counter inputs → td, td.td_us/valid → gap,
// gap.vz_mm_s → wear.vz_in_mm_s; wear_ratio / enable_wear_comp reach wear through the composite.
//
// Sequence (output `state`):
//   0 IDLE      generator off, vz = 0. A rising edge of `start` begins a cycle: the target depth
//               is the depth_mm input if > 0, else the depth_default_mm parameter.
//   1 APPROACH  generator on, vz = −approach_speed_mm_s until sparks are seen (td_count > 0) on
//               touch_cycles consecutive cycles; then touch_z_mm = z_mm, wear_mm is reset → DRILL.
//   2 DRILL     td → gap → wear → vz_cmd_mm_s (wear compensation only if enable_wear_comp).
//               An external gap servo replaces gap's Vz when the input vz_servo_mm_s is wired
//               (the config wires `<job>.drill.vz_servo_mm_s`, e.g. seed 003's fuzzy LUT servo):
//               vz_servo_mm_s (Z up positive, like vz_cmd_mm_s) clamped to gap's
//               [−v_feed_max_mm_s, +v_retract_max_mm_s] → wear → vz_cmd_mm_s. td and gap
//               still run (their outputs stay observable). A non-finite vz_servo_mm_s is a
//               broken signal: the feed stops (vz 0 into wear) and update() returns kFault.
//               Hole depth estimate (the electrode front is z − accumulated wear):
//                 depth_reached_mm = (touch_z_mm − z_mm) − (enable_wear_comp ? wear.wear_mm : 0)
//                 (output wear_mm: that estimated electrode wear of this cycle)
//               When it reaches the target → RETRACT. With `through` set, breakthrough_cycles
//               consecutive cycles without an ignited pulse (td_count = 0) once depth ≥
//               breakthrough_min_mm mean the front has left the work: breakthrough = true →
//               BREAKTHROUGH.
//   5 BREAKTHROUGH generator off, vz = −approach_speed_mm_s for overtravel_mm below the z of
//               the detection (clears the exit burr), then RETRACT; done = true at the end.
//   3 RETRACT   generator off, vz = +retract_speed_mm_s until z_mm ≥ touch_z_mm + clearance_mm
//               → DONE (vz = 0, done = true).
//   4 DONE      generator off, vz = 0; a new rising edge of `start` begins another cycle.
// The gap child creeps down at −approach_speed_mm_s while its Td window holds no ignited pulse
// (gap opened), so the cycle can never stall with vz = 0.
//
// Safe state (FAULT / ESTOP): generator off at once. If APPROACH or DRILL was running the state
// becomes RETRACT and Z backs off (to touch_z + clearance when drilling, else clearance_mm above
// the current z); a retract that completes in the safe state ends in IDLE (done stays false: the
// hole is not finished). `start` is ignored while the machine is in a safe state.
//
// Inputs tdr_us (> 0: the active condition's Tdr, else the parameter) and through.
// Input hold (feed hold): in APPROACH or DRILL the generator goes off and vz = 0 at once; the
// children are not stepped, so the cycle resumes where it was when hold drops.
// Child parameters: kg, tdr_default_us (gap) and hole_area_mm2, electrode_area_mm2 (wear) and
// td_window (td) are the composite's own and are copied into the children at configure time; kg and
// tdr_us are also copied on a runtime write. The other child parameters keep their defaults, except
// gap.idle_feed_mm_s = −approach_speed_mm_s.
//
// Accuracy on the simulator (drill preset, 20 mm, tests/programs): the hole ends ≈ 0.25 mm short
// with wear compensation (≈ 9 mm short without): eq. (8) estimates the wear from the bottom feed
// only, while side-wall sparks also wear the electrode (≈ 1.3 % more wear than estimated).
//
// RT-safety: update() and enter_safe_state() are RT-safe (noexcept, no allocation, no locks).
// Not thread-safe: the owning task calls every member except the pins (see pin.hpp).

#include <cstdint>
#include <vector>

#include "edm/blocks/gap_controller_p.hpp"
#include "edm/blocks/td_detector.hpp"
#include "edm/blocks/wear_compensator.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/composite_block.hpp"

namespace edm::programs {

struct DeepHoleDrillParams {
  double depth_default_mm{20.0};    // [mm] > 0, target hole depth when the input is 0
  double approach_speed_mm_s{0.5};  // [mm/s] in (0, 1], feed down until the first sparks
  std::int64_t touch_cycles{3};     // ≥ 1 consecutive cycles with sparks = touch
  double retract_speed_mm_s{5.0};   // [mm/s] > 0
  double clearance_mm{1.0};         // [mm] ≥ 0, retract to touch_z + this
  double wear_ratio_default{0.6};   // [-] ≥ 0, electrode/workpiece volume when the input is 0
  double kg{0.05};                  // [mm/s per µs] > 0 → gap.kg
  double tdr_default_us{8.0};  // [µs] > 0 → gap.tdr_default_us (while the tdr_us input ≤ 0)
  double hole_area_mm2{blocks::WearCompensatorParams{}.hole_area_mm2};            // → wear
  double electrode_area_mm2{blocks::WearCompensatorParams{}.electrode_area_mm2};  // → wear
  std::int64_t td_window{8};              // cycles, → td.window (load time only)
  std::int64_t breakthrough_cycles{300};  // ≥ 1 cycles without ignition = breakthrough (through)
  double breakthrough_min_mm{0.5};        // [mm] ≥ 0, no breakthrough before this depth
  double overtravel_mm{0.3};              // [mm] ≥ 0, feed on after breakthrough, then retract

  void visit(rt::ParamVisitor& v);
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class DeepHoleDrill final : public rt::BlockWithParams<DeepHoleDrillParams, rt::CompositeBlock> {
 public:
  enum class State : std::int64_t {
    kIdle = 0,
    kApproach = 1,
    kDrill = 2,
    kRetract = 3,
    kDone = 4,
    kBreakthrough = 5
  };

  DeepHoleDrill();

  /// RT-safe. kOk, or the worst status of the children stepped this cycle.
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;
  /// Non-RT. Refuses hole_area_mm2, electrode_area_mm2 and td_window (load time only).
  std::vector<rt::ParamError> stage_param(std::size_t index, const rt::ParamValue& v) override;

 protected:
  void visit_own_pins(rt::PinVisitor& v) override;
  std::vector<rt::ParamError> configure_self(const rt::BlockSetup& setup) override;
  void activate_self() noexcept override;
  void safe_state_self(const rt::SafeStateRequest& request) noexcept override;
  void params_changed() noexcept override;

 private:
  void set_state(State s) noexcept;
  void begin_cycle() noexcept;
  void begin_retract(double target_z) noexcept;

  blocks::TdDetector& td_;
  blocks::GapControllerP& gap_;
  blocks::WearCompensator& wear_;

  // Own pins.
  rt::Input<std::int64_t> td_sum_ns_, td_count_, n_open_, n_short_;
  rt::Input<double> z_mm_;
  rt::Input<bool> start_;
  rt::Input<double> depth_mm_;    // 0: use the parameter
  rt::Input<double> wear_ratio_;  // ≤ 0 (unwired): use the parameter
  rt::Input<bool> enable_wear_comp_{true};
  rt::Input<double> tdr_us_;  // ≤ 0 (unwired): the tdr_us parameter
  rt::Input<bool> through_;
  rt::Input<bool> hold_;        // a through hole: detect the breakthrough
  rt::Input<double> vz_servo_;  // wired: an external gap servo replaces gap's Vz in DRILL
  rt::Output<double> vz_cmd_mm_s_;
  rt::Output<bool> gen_on_;
  rt::Output<std::int64_t> state_;
  rt::Output<double> depth_reached_mm_, touch_z_mm_, wear_out_mm_;
  rt::Output<bool> done_;
  rt::Output<bool> breakthrough_;

  // Private cells the children's inputs are wired to (an input cannot be wired to an input).
  rt::Output<std::int64_t> c_td_sum_ns_, c_td_count_, c_n_open_, c_n_short_;
  rt::Output<double> c_wear_ratio_;
  rt::Output<bool> c_wear_enable_{true};
  rt::Output<bool> c_reset_wear_;
  rt::Output<double> c_tdr_us_;
  rt::Output<double> c_servo_vz_;  // gap's Vz or the external servo's → wear.vz_in_mm_s
  // Children's outputs read by the sequence.
  const rt::Output<double>* gap_vz_{nullptr};
  const rt::Output<double>* wear_vz_{nullptr};
  double servo_v_min_{0.0}, servo_v_max_{0.0};  // gap's clamp, applied to the external servo
  const rt::Output<double>* wear_mm_{nullptr};

  State state_value_{State::kIdle};
  bool prev_start_{false};
  std::int64_t spark_cycles_{0};
  std::int64_t dark_cycles_{0};    // consecutive DRILL cycles without an ignited pulse
  double breakthrough_z_mm_{0.0};  // z where the breakthrough was detected
  double target_depth_mm_{0.0};
  double retract_to_z_mm_{0.0};
  bool safe_retract_{false};  // the running retract was started by the safe state
};

}  // namespace edm::programs
