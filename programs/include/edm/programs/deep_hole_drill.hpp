#pragma once
// DeepHoleDrill: the deep-hole drilling cycle of seed 004 as a C++ PROGRAM type.
//
// Children (their pins and parameters are variables program.<instance>.<child>.<name>):
//   td    TdDetector       mean ignition delay over `td.window` cycles from the pulse counters
//   gap   GapControllerP   Vz = Kg·(Tdr − Td)                       (eq. 1)
//   wear  WearCompensator  vz_out = vz_in − Vd, Vd = θ·(A_hole/A_e)·|vz_in|, wear_mm = ∫Vd dt
//                          (eq. 8)
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
//                 depth_reached_mm = depth_done_mm + (touch_z_mm − z_mm)
//                                    − (enable_wear_comp ? wear.wear_mm : 0)
//                                    − spark_gap_offset_um·1e-3
//                 (depth_done_mm: the depth a resumed hole already had, 0 for a new one);
//                 resumed with the interrupted drill's state (resume_wear_mm > 0): touch_z_mm
//                 is resume_touch_z_mm and the wear is resume_wear_mm + this cycle's, so
//                 depth_reached_mm = (touch_z_mm − z_mm) − wear − spark_gap_offset_um·1e-3 as if
//                 never interrupted (wear_mm, the output, includes resume_wear_mm)
//                 (the front touches at the first-spark gap and drills one working gap above
//                 the bottom; spark_gap_offset_um is their difference, docs/blocks.md)
//                 (output wear_mm: that estimated electrode wear of this cycle)
//                 measured (contact_depth_mm > 0: the bottom found by touch at axis Z
//                 contact_z_mm, EdmJob's depth probe): touch_z_mm is contact_z_mm and
//                   depth_reached_mm = contact_depth_mm + (contact_z_mm − z_mm) − wear_mm
//                                      + contact_offset_um·1e-3
//                 (at the contact the front stood the touch-sensing distance above the bottom,
//                 drilling it stands one working gap above: contact_offset_um is their
//                 difference); no wear is counted (the compensator held at 0) while the axis
//                 is still above contact_z_mm + contact_offset_um·1e-3: the front has not yet
//                 reached the measured bottom, and the gap it closes there erodes nothing
//               When it reaches the target → RETRACT. With `through` set, breakthrough_cycles
//               consecutive cycles without an ignited pulse (td_count = 0) once depth ≥
//               breakthrough_min_mm mean the front has left the work: breakthrough = true →
//               BREAKTHROUGH.
//   5 BREAKTHROUGH generator off, vz = −approach_speed_mm_s for overtravel_mm below the z of
//               the detection (clears the exit burr), then RETRACT; done = true at the end.
//   3 RETRACT   generator off, vz = +retract_speed_mm_s until z_mm ≥ touch_z_mm + clearance_mm
//               → DONE (vz = 0, done = true).
//   4 DONE      generator off, vz = 0; a new rising edge of `start` begins another cycle.
// The gap child creeps down at gap.idle_feed_mm_s (< 0) while its Td window holds no ignited
// pulse (gap opened), so the cycle can never stall with vz = 0.
//
// Safe state (FAULT / ESTOP): generator off at once. If APPROACH or DRILL was running the state
// becomes RETRACT and Z backs off (to touch_z + clearance when drilling, else clearance_mm above
// the current z); a retract that completes in the safe state ends in IDLE (done stays false: the
// hole is not finished). `start` is ignored while the machine is in a safe state.
//
// Inputs tdr_us (> 0: the active condition's Tdr, else the gap child's tdr_default_us),
// wear_ratio (> 0: the condition's θ, else the wear child's wear_ratio_default) and through.
// Input hold (feed hold): in APPROACH or DRILL the generator goes off and vz = 0 at once; the
// children are not stepped, so the cycle resumes where it was when hold drops.
//
// Short circuits (DRILL). td pools a short as a pulse with Td ≈ 0 (gap truth, seed 004), so a
// short-dominated window makes the P law back off by itself. Besides that:
//   gap_short = td.short_ratio ≥ short_ratio_limit (0.9: a short-dominated td.window; the
//   occasional debris shorts of a loaded gap stay below it and are the P law's to handle);
//   while gap_short the Z command never points down (vz ≥ 0);
//   cycle_short = td.cycle_short_ratio ≥ short_ratio_limit (this cycle's own pulses, issue 31):
//   a short shorter than the window stops the feed in the cycle it shows (vz ≥ 0) without
//   waiting for the window. short_now = gap_short || cycle_short: the gap reads short, so no
//   feed toward the work; the retract child counts its consecutive cycles (with the feed stopped
//   at the first shorted cycle the window may never fill at a persistent contact: counting the
//   window alone let the drill sit at one without a retract or alarm 150). In APPROACH a cycle
//   that reads short is a touch (the gap has closed), with vz = 0 in it.
//   retract (ShortRetract, after retract.short_cycles consecutive short_now cycles, 5 here) backs
//   Z off along the path already drilled (retract.retract_distance_mm at retract_speed_mm_s),
//   walks forward again and hands back with a ramp (v_scale); zloop (PositionLoop) follows its
//   setpoint; the generator stays on. short_retracts counts them, short_time_s is the time
//   they took.
//   More than short_retracts_max retracts within short_retracts_window without the hole
//   advancing retract.progress_mm between them (a contact the retracts cannot clear; the
//   occasional shorts of a deep hole are each followed by progress): alarm 150 (kShortCircuit,
//   a fault) instead of another retract; the safe state then backs Z off by short_backoff_mm
//   with the generator off and holds (IDLE, done = false).
// Children and their parameters are variables of their own (`<instance>.gap.kg`, …), set in
// YAML under this block's params (`gap: {kg: 0.147}`). This program gives its children these
// defaults: gap.idle_feed_mm_s = −0.5 mm/s (the creep while the Td window holds no ignited
// pulse; keep it within [−approach_speed_mm_s … 0] yourself) and wear.wear_ratio_default = 0.6.
// The children are connected by member in bind_self():
//   td.{td_sum_ns,td_count,n_open,n_short} ← this block's inputs
//   gap.td_us, gap.valid ← td;   gap.tdr_us ← tdr_us
//   wear.wear_ratio ← wear_ratio;  wear.area_ratio ← area_ratio;  wear.enable ← enable_wear_comp
// and driven each cycle (Input::drive, no mirror output): wear.vz_in_mm_s, the servo command
// into the compensator (gap.vz_mm_s, or the external servo's when vz_servo_mm_s is wired:
// clamped, ramped after a retract, never down while the gap reads short); wear.reset_wear (true
// in the cycle the wear estimate restarts, at the touch); retract.enable, retract.short_detected
// (ShortGuard::step) and zloop.v_ff_mm_s (the retract setpoint's feed-forward).
//
// Accuracy on the simulator (drill preset, 20 mm, tests/programs): the hole ends ≈ 0.25 mm short
// with wear compensation (≈ 9 mm short without): eq. (8) estimates the wear from the bottom feed
// only, while side-wall sparks also wear the electrode (≈ 1.3 % more wear than estimated).
//
// RT-safety: update() and enter_safe_state() are RT-safe (noexcept, no allocation, no locks).
// Not thread-safe: the owning task calls every member except the pins (see pin.hpp).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "edm/blocks/gap_controller_p.hpp"
#include "edm/blocks/position_loop.hpp"
#include "edm/blocks/short_retract.hpp"
#include "edm/blocks/td_detector.hpp"
#include "edm/blocks/wear_compensator.hpp"
#include "edm/programs/machining_cycle.hpp"
#include "edm/programs/pulse_inputs.hpp"
#include "edm/programs/short_guard.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/composite_block.hpp"

namespace edm::programs {

struct DeepHoleDrillParams {
  double depth_default_mm{20.0};    // [mm] target hole depth while the depth_mm input is 0
  double approach_speed_mm_s{0.5};  // [mm/s] feed down until the first sparks
  double spark_gap_offset_um{0.0};  // [um] first-spark gap − working gap (depth origin)
  double contact_offset_um{0.0};    // [um] working gap − touch-sensing distance (measured origin)
  std::int64_t touch_cycles{3};     // consecutive cycles with sparks = touch
  double retract_speed_mm_s{5.0};   // [mm/s]
  double clearance_mm{1.0};         // [mm] retract to touch_z + this
  std::int64_t breakthrough_cycles{300};  // cycles without ignition = breakthrough (through)
  double breakthrough_min_mm{0.5};        // [mm] no breakthrough before this depth
  double overtravel_mm{0.3};              // [mm] feed on after breakthrough, then retract
  // Short circuits (seed 004: a short reads as feedback ≈ 0, so it must back the electrode off).
  ShortLimits shorts{};          // short_ratio_limit, short_retracts_max, short_retracts_window
  double short_backoff_mm{1.0};  // [mm] Z backs off this far on alarm 150, then holds

  void visit(rt::ParamVisitor& v);
};

class DeepHoleDrill final : public rt::BlockWithParams<DeepHoleDrillParams, rt::CompositeBlock>,
                            public MachiningCycle {
 public:
  /// The job was stopped by the operator (not a safe state): as the safe state does, the
  /// generator goes off and an approach or drilling cycle retracts (to the touch height plus
  /// clearance_mm) and ends in IDLE, done false — never left creeping down dark. RT-safe.
  void abort() noexcept override { safe_state_self(rt::SafeStateRequest{}); }
  /// MachiningCycle: from the start to DONE or IDLE it commands Z.
  [[nodiscard]] bool running() const noexcept override {
    return state_value_ != State::kIdle && state_value_ != State::kDone;
  }
  [[nodiscard]] AxisClaim axes() const noexcept override { return AxisClaim::z(vz_cmd_mm_s.get()); }
  [[nodiscard]] bool generator_on() const noexcept override { return gen_on.get(); }
  enum class State : std::int64_t {
    kIdle = 0,
    kApproach = 1,
    kDrill = 2,
    kRetract = 3,
    kDone = 4,
    kBreakthrough = 5
  };

  DeepHoleDrill();

  // Pins, listed in declaration order.
  PulseInputs pulses{pins_};  // td_sum_ns, td_count, n_open, n_short
  rt::Input<double> z_mm{pins_, "z_mm", "mm"};
  rt::Input<bool> start{pins_, "start"};
  rt::Input<double> depth_mm{pins_, "depth_mm", "mm"};  // 0: use depth_default_mm
  // The depth the hole already has (run from a block after an interruption): the first sparks
  // strike at its bottom, so the depth counts from there. Read at the start of a cycle; ≤ 0 or
  // not finite: a new hole.
  rt::Input<double> depth_done_mm{pins_, "depth_done_mm", "mm"};
  // A resumed hole whose interrupted drill's state is known (resume_wear_mm > 0 with
  // depth_done_mm > 0): the depth counts on from that drill's touch point and wear, not from the
  // new first sparks (inside a hole they may strike the wall well above the bottom).
  rt::Input<double> resume_touch_z_mm{pins_, "resume_touch_z_mm", "mm"};
  rt::Input<double> resume_wear_mm{pins_, "resume_wear_mm", "mm"};
  // A hole whose depth was measured by touch (EdmJob's depth probe): contact_depth_mm > 0 is its
  // measured depth and contact_z_mm the axis Z at which the electrode touched its bottom; the
  // depth counts on from there (takes precedence over the resume inputs).
  rt::Input<double> contact_z_mm{pins_, "contact_z_mm", "mm"};
  rt::Input<double> contact_depth_mm{pins_, "contact_depth_mm", "mm"};
  rt::Input<double> wear_ratio{pins_,
                               "wear_ratio"};  // ≤ 0 (unwired): the wear child's wear_ratio_default
  rt::Input<double> area_ratio{pins_, "area_ratio"};  // ≤ 0 (unwired): the wear child's areas
  rt::Input<bool> enable_wear_comp{pins_, "enable_wear_comp", "", true};
  rt::Input<double> tdr_us{pins_, "tdr_us", "us"};  // ≤ 0 (unwired): the gap child's tdr_default_us
  rt::Input<bool> through{pins_, "through"};        // a through hole: detect the breakthrough
  rt::Input<bool> hold{pins_, "hold"};
  // Feed override 0 … 1.5 (unwired 1): scales the approach and the downward feed cap, never a
  // retract or backing off.
  rt::Input<double> feed_override{pins_, "feed_override", "", 1.0};
  rt::Input<double> vz_servo_mm_s{
      pins_, "vz_servo_mm_s", "mm/s"};  // wired: an external gap servo replaces gap's Vz in DRILL
  rt::Output<double> vz_cmd_mm_s{pins_, "vz_cmd_mm_s", "mm/s"};
  rt::Output<bool> gen_on{pins_, "gen_on"};
  rt::Output<std::int64_t> state{pins_, "state"};
  rt::Output<double> depth_reached_mm{pins_, "depth_reached_mm", "mm"};
  rt::Output<double> touch_z_mm{pins_, "touch_z_mm", "mm"};
  rt::Output<double> wear_mm{pins_, "wear_mm", "mm"};
  rt::Output<bool> done{pins_, "done"};
  rt::Output<bool> breakthrough{pins_, "breakthrough"};
  rt::Output<double> short_time_s{pins_, "short_time_s",
                                  "s"};  // time spent retracting and resuming in this hole
  // gap_short, short_retracts (retracts in this hole), cycle_short, short_now.
  ShortPins short_pins{pins_};

 protected:
  std::vector<rt::ParamError> configure_self(const rt::BlockSetup& setup) override;
  void bind_self() override;
  void activate_self() noexcept override;
  void safe_state_self(const rt::SafeStateRequest& request) noexcept override;
  /// RT-safe. kOk, or the worst status of the children stepped this cycle.
  rt::BlockStatus update_self(const rt::CycleContext& ctx) noexcept override;

 private:
  /// The feed override input, clamped to [0, 1.5]; not finite: 0 (stop feeding). RT-safe.
  [[nodiscard]] double feed_scale() const noexcept;
  /// The window (gap_short) or this cycle's own pulses (cycle_short) read short. RT-safe.
  [[nodiscard]] bool feed_stopped() const noexcept { return short_pins.short_now.get(); }
  void set_state(State s) noexcept;
  void begin_cycle() noexcept;
  void begin_retract(double target_z) noexcept;
  /// One DRILL cycle of the short handling; true while the retract owns the Z command.
  bool handle_short(const rt::CycleContext& ctx, double z, rt::BlockStatus& status) noexcept;

  blocks::TdDetector& td_;
  blocks::GapControllerP& gap_;
  blocks::WearCompensator& wear_;
  blocks::ShortRetract& retract_;
  blocks::PositionLoop& zloop_;
  rt::Machine* machine_{nullptr};
  const char* source_{""};  // this block's instance name, for alarm 150
  std::string source_name_;

  State state_value_{State::kIdle};
  bool prev_start_{false};
  std::int64_t spark_cycles_{0};
  std::int64_t dark_cycles_{0};    // consecutive DRILL cycles without an ignited pulse
  double breakthrough_z_mm_{0.0};  // z where the breakthrough was detected
  double target_depth_mm_{0.0};
  double depth_done_mm_{0.0};  // depth_done_mm at the start of the cycle
  bool resume_{false};         // counting on from an interrupted drill's touch and wear
  bool measured_{false};       // counting on from a measured bottom (contact_depth_mm > 0)
  double contact_z_mm_{0.0};
  double contact_depth_mm_{0.0};
  double resume_touch_z_mm_{0.0};
  double resume_wear_mm_{0.0};
  double retract_to_z_mm_{0.0};
  bool safe_retract_{false};  // the running retract was started by the safe state
  double last_z_sp_mm_{0.0};
  ShortGuard guard_;
};

}  // namespace edm::programs
