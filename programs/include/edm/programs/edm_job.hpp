#pragma once
// EdmJob: the job sequencer — runs the part program the runtime owns (rt::JobStore, loaded by the
// bridge's program.commit or by a test) block by block on the simulated or real machine.
//
// It is machine-independent: it sequences the motion blocks (moves, dwells, M-functions,
// conditions, hold/resume/stop, run from a line, dry run, MDI, the job's figures) and hands the
// machining to its cycles (MachiningCycle, docs/runtime.md "Machining cycles").
//
// Children (their pins and parameters are variables program.<instance>.<child>.<name>, their
// parameters set in YAML under this block's params, e.g. `finish: {orbit: {kr: 1e-4}}`,
// `pz: {kv: 20}`):
//   drill   DeepHoleDrill   cycle: gap-controlled drilling (approach, touch, drill, retract)
//   finish  WallFinish      cycle: orbit finishing (polarity switch, orbit eq. 20-21, centre)
//   lin     LinearInterpolator  rapids and linear moves (eq. 12-13 in XYZ)
//   arc     CircularInterpolator  G02/G03 in XY (eq. 14-19)
//   px/py/pz PositionLoop   the three axis loops following lin/arc (and holding still otherwise)
//   manual  ManualMotion    the operator's reference, jog and touch-off (manual_motion.hpp):
//                           enabled while the machine is READY and no job runs. Its inputs
//                           ref_x/ref_y/ref_z and contact and its outputs touch_mode, pos_set_*
//                           and pos_value_*_mm are wired in YAML to the driver
//                           (`job.manual.contact: io.contact`, …).
//   probe   DepthProbe      cycle: a blind hole's depth measured by touch (depth_probe.hpp),
//                           on with `probe: {enable: true}` and touch sensing wired
//   wire    WireCut         cycle: a wire machine's cut blocks, fed along the path by the gap
//                           servo on gap_voltage_v, back along it on a short (wire_cut.hpp)
//   axes    AxisArbiter     who commands each axis: the safe state, manual motion, a running
//                           cycle, the loops (axis_arbiter.hpp). Its vx/vy/vz_cmd_mm_s are the
//                           job's axis commands (`io.vx_cmd: job.axes.vx_cmd_mm_s`).
// The job drives its children's inputs (Input::drive: the drill's depth and start, the
// interpolators' moves, the loops' references, the feed override, …), readable as those
// children's inputs (`cnc.job.lin.lx_mm`); no output of the job exists only to feed a child.
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
//              With the probe (DepthProbe), the block runs rough drilling, touches, the
//              finish from the measured bottom and a check touch; its moves run here.
//   orbit_finish  finish.final_offset_mm = final_radius_mm − orbit_radius_offset_mm (the
//              electrode radius plus the finishing side gap, calibrated: docs/blocks.md); Z held.
//   end        finishes the job.
// The loops' v_max_mm_s must be at least 1.5 × rapid_speed_mm_s (checked at load).
// Supervision is the runtime's (machine.safety, docs/safety.md): soft limits → alarm 141,
// following error → alarm 140, whatever program runs.
//
// Outputs for the I/O image: gen_arm, gen_on, polarity_positive, on_time_us, off_time_us,
// servo_ref_v, flushing_on, rotation_on (the axes': the axes child's); progress: state,
// block_index, line, jobs_finished, dry_run.
// Job figures job_time_s, job_pulses, job_shorts, job_arcs, job_depth_mm, job_wear_mm: see
// job_figures.hpp.
// RT-safety: update() and enter_safe_state() never allocate, lock or throw. Needs the runtime's
// BlockSetup (machine, job, tables): configure() reports an error without them.

#include <array>
#include <cstdint>
#include <vector>

#include "edm/blocks/circular_interpolator.hpp"
#include "edm/blocks/linear_interpolator.hpp"
#include "edm/blocks/position_loop.hpp"
#include "edm/machining/machine_tables.hpp"
#include "edm/machining/motion_block.hpp"
#include "edm/programs/axis_arbiter.hpp"
#include "edm/programs/deep_hole_drill.hpp"
#include "edm/programs/depth_probe.hpp"
#include "edm/programs/job_figures.hpp"
#include "edm/programs/machining_cycle.hpp"
#include "edm/programs/manual_motion.hpp"
#include "edm/programs/pulse_inputs.hpp"
#include "edm/programs/wall_finish.hpp"
#include "edm/programs/wire_cut.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/composite_block.hpp"
#include "edm/runtime/electrode.hpp"
#include "edm/runtime/job.hpp"
#include "edm/runtime/xyz_pins.hpp"

namespace edm::programs {

struct EdmJobParams {
  double rapid_speed_mm_s{10.0};          // [mm/s]
  double feed_default_mm_s{2.0};          // [mm/s] linear/arc feed when the block has none
  double orbit_radius_offset_mm{0.5549};  // [mm] electrode radius + finishing side gap
  rt::Duration polarity_settle{std::chrono::milliseconds(20)};

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
  rt::Xyz<rt::Input<double>> pos{pins_, {"x_mm", "y_mm", "z_mm"}, "mm"};
  rt::Input<double> gap_voltage_v{pins_, "gap_voltage_v", "V"};  // the cycle's mean (wire cuts)
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
  rt::Output<bool> dry_run{pins_, "dry_run"};  // the running job is a dry run
  // Electrode length compensation (rt::Electrode): the estimate now (0: unknown) and the Z shift
  // of the move running (length now − the length its work frame's Z was set with).
  rt::Output<double> electrode_mm{pins_, "electrode_mm", "mm"};
  rt::Output<double> z_comp_mm{pins_, "z_comp_mm", "mm"};

 protected:
  std::vector<rt::ParamError> configure_self(const rt::BlockSetup& setup) override;
  void bind_self() override;
  void activate_self() noexcept override;
  void safe_state_self(const rt::SafeStateRequest& request) noexcept override;
  rt::BlockStatus update_self(const rt::CycleContext& ctx) noexcept override;

 private:
  enum class Step : std::uint8_t { kEnter, kLoad, kGo, kBusy, kSettle };
  class ProbeMovesOfJob;  // the depth probe's moves on this job (edm_job_drill.cpp)

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
  /// A wire cut (edm_job_wire.cpp): the wire child feeds along the block's path.
  bool run_cut(const machining::MotionBlock& b, const rt::CycleContext& ctx, bool hold) noexcept;
  /// M00 / M01: the machine holds (the generator off) until the operator resumes.
  bool run_program_stop(const rt::CycleContext& ctx) noexcept;
  /// Starts the drill child to `depth_mm`, its depth counted from `from`.
  void start_drill(double depth_mm, const DrillFrom& from) noexcept;
  void set_hold(bool hold) noexcept;  // the cycles' feed hold
  void set_reference(double x, double y, double z, double vx, double vy, double vz) noexcept;
  void hold_position() noexcept;
  /// Sets move_from_* (see there) for the move that starts this cycle.
  void set_move_from() noexcept;
  void stop_outputs() noexcept;
  /// Every loop in position and every axis standing still (≤ kStillSpeed for kStillCycles): the
  /// loops' window alone also holds while an axis sweeps through it at speed.
  [[nodiscard]] bool in_position() const noexcept;
  /// The running cycles' axes to the arbiter, then the arbiter's decision. RT-safe.
  rt::BlockStatus command_axes(const rt::CycleContext& ctx) noexcept;
  /// The Z shift that puts the tip where block b's work frame assumed it: the electrode length
  /// lost since the frame's Z was set (shorter: lower). 0 without a known length on both sides.
  [[nodiscard]] double z_compensation(const machining::MotionBlock& b) const noexcept;
  /// The electrode estimate is the length at the job's start less the wear the job estimated
  /// (job_wear_mm, seed 004 eq. 8). RT-safe.
  void wear_electrode() noexcept;

  DeepHoleDrill& drill_;
  WallFinish& finish_;
  blocks::LinearInterpolator& lin_;
  blocks::CircularInterpolator& arc_;
  blocks::PositionLoop& px_;
  blocks::PositionLoop& py_;
  blocks::PositionLoop& pz_;
  ManualMotion& manual_;
  DepthProbe& probe_;
  AxisArbiter& axes_;
  WireCut& wire_;
  std::array<MachiningCycle*, 2> cycles_;
  rt::Machine* machine_{nullptr};
  rt::ManualControl* manual_control_{nullptr};
  rt::JobStore* job_{nullptr};
  const machining::MachineTables* tables_{nullptr};
  rt::Electrode* electrode_{nullptr};
  JobFigures figures_{pins_};
  double electrode_at_start_mm_{0.0};  // the estimate when the running job began (0: unknown)
  double resumed_wear_mm_{0.0};        // wear of earlier jobs that resumed holes count on from

  State state_value_{State::kIdle};
  Step step_{Step::kEnter};
  double hold_x_{0.0}, hold_y_{0.0}, hold_z_{0.0};  // references while no move is interpolated
  bool hold_valid_{false};  // hold_* are set (false after activation and in a safe state)
  // Where the next interpolated move starts: the reference the last move ended on while it is
  // valid (a job's moves chain on their references, so the mechanics' settling error never
  // accumulates from block to block), else the actual position (after power-on, manual motion, a
  // safe state).
  double move_from_x_{0.0}, move_from_y_{0.0}, move_from_z_{0.0};
  double feed_override_{1.0};  // the operator's, read once a cycle (Machine::feed_override)
  double last_x_{0.0}, last_y_{0.0}, last_z_{0.0};  // the positions of the previous cycle
  std::int64_t still_cycles_{0};                    // consecutive cycles every axis stood still
  rt::TimePoint wait_until_{};
  const machining::Condition* condition_{nullptr};
  bool polarity_positive_value_{false};
  bool cut_continuing_{false};   // the previous block was a cut: the wire's history goes on
  bool cutting_{false};          // a cut runs this cycle (the generator's on)
  bool drill_returning_{false};  // the drill is done; rapid back to the block's start
  machining::MotionBlock drill_return_{};
  machining::MotionBlock probe_move_{};
};

}  // namespace edm::programs
