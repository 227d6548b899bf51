#pragma once
// EdmJob: the job sequencer — runs the part program the runtime owns (rt::JobStore, loaded by the
// bridge's program.commit or by a test) block by block on the simulated or real machine.
//
// Children (their pins and parameters are variables program.<instance>.<child>.<name>, their
// parameters set in YAML under this block's params, e.g. `finish: {orbit: {kr: 1e-4}}`,
// `pz: {kv: 20}`):
//   drill   DeepHoleDrill   gap-controlled drilling blocks (approach, touch, drill, retract)
//   finish  WallFinish      orbit-finishing blocks (polarity switch, orbit eq. 20-21, centre)
//   lin     LinearInterpolator  rapids and linear moves (eq. 12-13 in XYZ)
//   arc     CircularInterpolator  G02/G03 in XY (eq. 14-19)
//   px/py/pz PositionLoop   the three axis loops following lin/arc (and holding still otherwise)
//   manual  ManualMotion    the operator's reference, jog and touch-off (manual_motion.hpp):
//                           enabled while the machine is READY and no job runs; while it is
//                           active it drives the axes. Its inputs ref_x/ref_y/ref_z and contact
//                           and its outputs touch_mode, pos_set_* and pos_value_*_mm are wired
//                           in YAML to the driver (`job.manual.contact: io.contact`, …).
//
// Sequence (output `state`): 0 IDLE — when the machine is RUNNING and a program is loaded, the
// job begins (JobStore::rt_begin) → 1 RUN: the current block is executed; when it completes the
// store advances. At the end block or past the last block the job finishes (kFinished) and the
// machine is commanded back to READY. A job does not begin while ManualControl says the machine
// must be referenced first (manual.reference_required): the machine is commanded back to READY.
// A dry run (StartOptions::dry_run) runs every move with the generator disarmed and skips the
// drilling and orbit-finishing blocks (the electrode stays above the work). An operator stop
// (machine READY), FAULT or ESTOP while running aborts the job (kAborted); the children's safe
// states stop the axes, switch the generator off and back Z off. HOLD pauses interpolated moves and
// dwells at once, and a drilling block and an orbit-finishing block at once too (the children's
// `hold`: generator off, axes still, resumed where they were).
//
// Blocks (machining::MotionKind):
//   condition  E<n>: the condition's polarity, on/off time, servo reference, Tdr and wear ratio
//              become the outputs / the drill's inputs; E0 disarms the generator. A polarity
//              change waits polarity_settle with the generator off.
//   rotation / flushing  set the outputs.      dwell  waits dwell_s.
//   rapid / linear   lin interpolates from the actual position to the target (rapid at
//              rapid_speed_mm_s, linear at the block's feed or feed_default_mm_s); generator off
//              during rapids; done when lin is done and every axis is in position.
//   arc_cw / arc_ccw  arc interpolates in XY (centre, end, turns), Z held; then in position.
//   drill      drill.depth_mm = the block's depth_mm (below the work frame's Z0), or −target.z
//              for a block without one (machine Z0 is the work surface); drill.depth_done_mm =
//              depth_done_mm (a resumed hole); the depth is measured from the first sparks, through
//              = false, wear ratio and Tdr of the active condition; XY held by px/py; when the
//              drill child is DONE (after its retract) a rapid takes the electrode back to where
//              the block began, so a drilling block ends at its start point (the G-code
//              interpreter's current point after it, docs/gcode.md).
//              With probe_depth (and touch sensing wired to manual.contact), a blind hole's
//              depth is measured, not estimated (docs/blocks.md "The depth probe"):
//                rough    the drill to depth − probe_margin_mm (eq. 8's estimate);
//                bottom   touch −Z on the hole's bottom (manual's touch): axis Z z_b;
//                surface  up to the block's start Z, over by (probe_dx_mm, probe_dy_mm), touch
//                         −Z on the work's surface: z_s; measured depth d1 = z_s − z_b (one
//                         electrode, one touch-sensing distance: the wear cancels);
//                finish   back into the hole, the drill from the contact (contact_z_mm = z_b,
//                         contact_depth_mm = d1) to the depth;
//                check    touch the bottom again: z_b2; the depth measured,
//                         d = d1 + (z_b − z_b2) − the finish's wear (eq. 8 over ≈ margin only)
//                         → measured_depth_mm, the job's depth figure.
//              A touch that finds nothing (no contact within manual.touch_max_mm, already in
//              contact) ends the probe: probe_failures counts it and the rest is drilled on the
//              estimate (as a resumed hole), so the hole is still finished.
//   orbit_finish  finish.final_offset_mm = final_radius_mm − orbit_radius_offset_mm (the
//              electrode radius plus the finishing side gap, calibrated: docs/blocks.md); Z held.
//   end        finishes the job.
// Connected by member in bind_self(): the pulse counters and positions follow this block's
// inputs; every other child input reads one of this block's outputs (drill_start, feed_hold,
// lin_*, arc_*, x_ref_mm, …: the signals the sequence gives its children, observable as
// variables). The loops' v_max_mm_s must be at least 1.5 × rapid_speed_mm_s (checked at load).
// Supervision is the runtime's (machine.safety, docs/safety.md): soft limits → alarm 141,
// following error → alarm 140, whatever program runs.
//
// Outputs for the I/O image: vx/vy/vz_cmd_mm_s, gen_arm, gen_on, polarity_positive,
// on_time_us, off_time_us, servo_ref_v, flushing_on, rotation_on; progress: state, block_index,
// line, jobs_finished.
// Job figures job_time_s, job_pulses, job_shorts, job_arcs, job_depth_mm, job_wear_mm: see
// job_figures.hpp.
// RT-safety: update() and enter_safe_state() never allocate, lock or throw. Needs the runtime's
// BlockSetup (machine, job, tables): configure() reports an error without them.

#include <cstdint>
#include <vector>

#include "edm/blocks/circular_interpolator.hpp"
#include "edm/blocks/linear_interpolator.hpp"
#include "edm/blocks/position_loop.hpp"
#include "edm/machining/machine_tables.hpp"
#include "edm/machining/motion_block.hpp"
#include "edm/programs/deep_hole_drill.hpp"
#include "edm/programs/job_figures.hpp"
#include "edm/programs/manual_motion.hpp"
#include "edm/programs/pulse_inputs.hpp"
#include "edm/programs/wall_finish.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/composite_block.hpp"
#include "edm/runtime/job.hpp"

namespace edm::programs {

struct EdmJobParams {
  double rapid_speed_mm_s{10.0};          // [mm/s]
  double feed_default_mm_s{2.0};          // [mm/s] linear/arc feed when the block has none
  double orbit_radius_offset_mm{0.5549};  // [mm] electrode radius + finishing side gap
  rt::Duration polarity_settle{std::chrono::milliseconds(20)};
  // The depth probe (issue 20 f): a blind hole's depth measured by touch, not estimated.
  bool probe_depth{false};      // on: drill, touch the bottom and the surface, drill the rest
  double probe_margin_mm{0.1};  // [mm] the first drilling stops this much short of the depth
  double probe_dx_mm{2.0};      // [mm] where the surface is touched, relative to the hole
  double probe_dy_mm{0.0};      // [mm]
  double probe_clear_mm{0.2};   // [mm] a touch starts this far above the expected contact

  void visit(rt::ParamVisitor& v);
};

class EdmJob final : public rt::BlockWithParams<EdmJobParams, rt::CompositeBlock> {
 public:
  enum class State : std::int64_t { kIdle = 0, kRun = 1 };

  EdmJob();

  // Pins, listed in declaration order.
  PulseInputs pulses{pins_};  // td_sum_ns, td_count, n_open, n_short
  rt::Input<std::int64_t> n_normal{pins_, "n_normal"};
  rt::Input<std::int64_t> n_transient_arc{pins_, "n_transient_arc"};
  rt::Input<std::int64_t> n_stable_arc{pins_, "n_stable_arc"};
  rt::Input<double> x_mm{pins_, "x_mm", "mm"};
  rt::Input<double> y_mm{pins_, "y_mm", "mm"};
  rt::Input<double> z_mm{pins_, "z_mm", "mm"};
  rt::Output<double> vx_cmd_mm_s{pins_, "vx_cmd_mm_s", "mm/s"};
  rt::Output<double> vy_cmd_mm_s{pins_, "vy_cmd_mm_s", "mm/s"};
  rt::Output<double> vz_cmd_mm_s{pins_, "vz_cmd_mm_s", "mm/s"};
  rt::Output<bool> gen_arm{pins_, "gen_arm"};
  rt::Output<bool> gen_on{pins_, "gen_on"};
  rt::Output<bool> polarity_positive{pins_, "polarity_positive"};
  rt::Output<bool> flushing_on{pins_, "flushing_on"};
  rt::Output<bool> rotation_on{pins_, "rotation_on"};
  rt::Output<double> on_time_us{pins_, "on_time_us", "us"};
  rt::Output<double> off_time_us{pins_, "off_time_us", "us"};
  rt::Output<double> servo_ref_v{pins_, "servo_ref_v", "V"};
  rt::Output<std::int64_t> state{pins_, "state"};
  rt::Output<std::int64_t> block_index{pins_, "block_index"};
  rt::Output<std::int64_t> line{pins_, "line"};
  rt::Output<std::int64_t> jobs_finished{pins_, "jobs_finished"};
  // The signals the sequence gives its children.
  rt::Output<bool> drill_start{pins_, "drill_start"};
  rt::Output<bool> finish_start{pins_, "finish_start"};
  rt::Output<bool> feed_hold{pins_, "feed_hold"};
  rt::Output<double> drill_depth_mm{pins_, "drill_depth_mm", "mm"};
  rt::Output<double> drill_depth_done_mm{pins_, "drill_depth_done_mm", "mm"};
  rt::Output<double> drill_resume_touch_z_mm{pins_, "drill_resume_touch_z_mm", "mm"};
  rt::Output<double> drill_resume_wear_mm{pins_, "drill_resume_wear_mm", "mm"};
  rt::Output<double> drill_contact_z_mm{pins_, "drill_contact_z_mm", "mm"};
  rt::Output<double> drill_contact_depth_mm{pins_, "drill_contact_depth_mm", "mm"};
  // The depth probe: its step (Probe), the last hole's measured depth (0: none measured) and the
  // probes that found no contact.
  rt::Output<std::int64_t> probe_step{pins_, "probe_step"};
  rt::Output<double> measured_depth_mm{pins_, "measured_depth_mm", "mm"};
  rt::Output<std::int64_t> probe_failures{pins_, "probe_failures"};
  rt::Output<bool> manual_enable{pins_, "manual_enable"};
  rt::Output<bool> dry_run{pins_, "dry_run"};
  rt::Output<double> wear_ratio{pins_, "wear_ratio"};
  rt::Output<double> area_ratio{pins_, "area_ratio"};
  rt::Output<double> tdr_us{pins_, "tdr_us", "us"};
  rt::Output<double> finish_final_offset_mm{pins_, "finish_final_offset_mm", "mm"};
  rt::Output<double> finish_start_offset_mm{pins_, "finish_start_offset_mm", "mm"};
  rt::Output<double> finish_feed_mm_min{pins_, "finish_feed_mm_min", "mm/min"};
  // The operator's feed override (Machine::feed_override): rapids, feeds, the orbit feed and the
  // drilling feed cap.
  rt::Output<double> feed_override{pins_, "feed_override", "", 1.0};
  rt::Output<double> lin_override{pins_, "lin_override", "", 1.0};  // rapids: at most 1
  rt::Output<bool> lin_start{pins_, "lin_start"};
  rt::Output<bool> lin_hold{pins_, "lin_hold"};
  rt::Output<bool> lin_load{pins_, "lin_load"};
  rt::Output<double> lin_lx_mm{pins_, "lin_lx_mm", "mm"};
  rt::Output<double> lin_ly_mm{pins_, "lin_ly_mm", "mm"};
  rt::Output<double> lin_lz_mm{pins_, "lin_lz_mm", "mm"};
  rt::Output<double> lin_feed_mm_min{pins_, "lin_feed_mm_min", "mm/min"};
  rt::Output<bool> arc_start{pins_, "arc_start"};
  rt::Output<bool> arc_hold{pins_, "arc_hold"};
  rt::Output<bool> arc_load{pins_, "arc_load"};
  rt::Output<bool> arc_cw{pins_, "arc_cw"};
  rt::Output<bool> arc_full_circle{pins_, "arc_full_circle"};
  rt::Output<std::int64_t> arc_turns{pins_, "arc_turns"};
  rt::Output<double> arc_i_mm{pins_, "arc_i_mm", "mm"};
  rt::Output<double> arc_j_mm{pins_, "arc_j_mm", "mm"};
  rt::Output<double> arc_ex_mm{pins_, "arc_ex_mm", "mm"};
  rt::Output<double> arc_ey_mm{pins_, "arc_ey_mm", "mm"};
  rt::Output<double> arc_feed_mm_min{pins_, "arc_feed_mm_min", "mm/min"};
  // Where the next interpolated move starts: the reference the last move ended on while it is
  // valid (a job's moves chain on their references, so the mechanics' settling error never
  // accumulates from block to block), else the actual position (after power-on, manual motion, a
  // safe state).
  rt::Output<double> move_from_x_mm{pins_, "move_from_x_mm", "mm"};
  rt::Output<double> move_from_y_mm{pins_, "move_from_y_mm", "mm"};
  rt::Output<double> move_from_z_mm{pins_, "move_from_z_mm", "mm"};
  rt::Output<double> x_ref_mm{pins_, "x_ref_mm", "mm"};
  rt::Output<double> y_ref_mm{pins_, "y_ref_mm", "mm"};
  rt::Output<double> z_ref_mm{pins_, "z_ref_mm", "mm"};
  rt::Output<double> vx_ff_mm_s{pins_, "vx_ff_mm_s", "mm/s"};
  rt::Output<double> vy_ff_mm_s{pins_, "vy_ff_mm_s", "mm/s"};
  rt::Output<double> vz_ff_mm_s{pins_, "vz_ff_mm_s", "mm/s"};
  rt::Output<bool> loop_enable{pins_, "loop_enable"};

 protected:
  std::vector<rt::ParamError> configure_self(const rt::BlockSetup& setup) override;
  void bind_self() override;
  void activate_self() noexcept override;
  void safe_state_self(const rt::SafeStateRequest& request) noexcept override;
  rt::BlockStatus update_self(const rt::CycleContext& ctx) noexcept override;

 private:
  enum class Step : std::uint8_t { kEnter, kLoad, kGo, kBusy, kSettle };

  void finish_job(rt::JobOutcome outcome) noexcept;
  void select_condition(int e) noexcept;
  /// Executes the current block one cycle; true when it is complete.
  bool run_block(const machining::MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                 rt::BlockStatus& status) noexcept;
  bool run_linear(const machining::MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                  rt::BlockStatus& status) noexcept;
  bool run_arc(const machining::MotionBlock& b, const rt::CycleContext& ctx, bool hold,
               rt::BlockStatus& status) noexcept;
  bool run_drill(const machining::MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                 rt::BlockStatus& status) noexcept;
  bool run_finish(const machining::MotionBlock& b, bool hold) noexcept;
  /// The depth probe's steps between the drillings (the rapids and touches).
  void run_probe(const rt::CycleContext& ctx, bool hold, rt::BlockStatus& status) noexcept;
  /// A rapid of the probe to (x, y, z); true when it has arrived.
  bool probe_rapid(double x, double y, double z, const rt::CycleContext& ctx, bool hold,
                   rt::BlockStatus& status) noexcept;
  /// A −Z touch of the probe; true when it has ended (ok: contact at z).
  bool probe_touch(const rt::CycleContext& ctx, bool& ok, double& z) noexcept;
  void start_drill(double depth_mm) noexcept;
  void set_probe(std::int64_t step) noexcept;
  void set_reference(double x, double y, double z, double vx, double vy, double vz) noexcept;
  void hold_position() noexcept;
  /// Sets move_from_* (see there) for the move that starts this cycle.
  void set_move_from() noexcept;
  void stop_outputs() noexcept;
  /// Every loop in position and every axis standing still (≤ kStillSpeed for kStillCycles): the
  /// loops' window alone also holds while an axis sweeps through it at speed.
  [[nodiscard]] bool in_position() const noexcept;

  DeepHoleDrill& drill_;
  WallFinish& finish_;
  blocks::LinearInterpolator& lin_;
  blocks::CircularInterpolator& arc_;
  blocks::PositionLoop& px_;
  blocks::PositionLoop& py_;
  blocks::PositionLoop& pz_;
  ManualMotion& manual_;
  rt::Machine* machine_{nullptr};
  rt::ManualControl* manual_control_{nullptr};
  rt::JobStore* job_{nullptr};
  const machining::MachineTables* tables_{nullptr};
  JobFigures figures_{pins_};

  State state_value_{State::kIdle};
  Step step_{Step::kEnter};
  double hold_x_{0.0}, hold_y_{0.0}, hold_z_{0.0};  // references while no move is interpolated
  bool hold_valid_{false};  // hold_* are set (false after activation and in a safe state)
  double last_x_{0.0}, last_y_{0.0}, last_z_{0.0};  // the positions of the previous cycle
  std::int64_t still_cycles_{0};                    // consecutive cycles every axis stood still
  rt::TimePoint wait_until_{};
  const machining::Condition* condition_{nullptr};
  bool polarity_positive_value_{false};
  bool drill_returning_{false};  // the drill is done; rapid back to the block's start
  machining::MotionBlock drill_return_{};
  // The depth probe (run_drill with probe_depth).
  std::int64_t probe_{0};     // 0: off (the drilling block runs without it); see edm_job_drill.cpp
  bool probe_moving_{false};  // a probe rapid or touch has started
  bool probe_fallback_{false};  // a touch failed: the rest is drilled on the estimate
  double probe_x_{0.0}, probe_y_{0.0}, probe_z_start_{0.0};
  double probe_depth_mm_{0.0};  // the block's depth
  double probe_rough_mm_{0.0};  // the rough drilling's depth
  double probe_z_low_{0.0};     // the lowest axis Z of the drilling that ran last
  double probe_z_b_{0.0};       // the bottom's contact
  double probe_d1_{0.0};        // the depth measured before the finish
  double probe_wear_rough_{0.0};
  double probe_rough_touch_z_{0.0};
  double probe_rough_reached_{0.0};
  machining::MotionBlock probe_move_{};
};

}  // namespace edm::programs
