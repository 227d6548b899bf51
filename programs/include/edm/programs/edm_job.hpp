#pragma once
// EdmJob: the job sequencer — runs the part program the runtime owns (rt::JobStore, loaded by the
// bridge's program.commit or by a test) block by block on the simulated or real machine.
//
// Children (variables program.<instance>.<child>.<pin>):
//   drill   DeepHoleDrill   gap-controlled drilling blocks (approach, touch, drill, retract)
//   finish  WallFinish      orbit-finishing blocks (polarity switch, orbit eq. 20-21, centre)
//   lin     LinearInterpolator  rapids and linear moves (eq. 12-13 in XYZ)
//   arc     CircularInterpolator  G02/G03 in XY (eq. 14-19)
//   px/py/pz PositionLoop   the three axis loops following lin/arc (and holding still otherwise)
//
// Sequence (output `state`): 0 IDLE — when the machine is RUNNING and a program is loaded, the
// job begins (JobStore::rt_begin) → 1 RUN: the current block is executed; when it completes the
// store advances. At the end block or past the last block the job finishes (kFinished) and the
// machine is commanded back to READY. An operator stop (machine READY), FAULT or ESTOP while
// running aborts the job (kAborted); the children's safe states stop the axes, switch the
// generator off and back Z off. HOLD pauses interpolated moves and dwells at once, and a drilling
// block and an orbit-finishing block at once too (the children's `hold`: generator off, axes
// still, resumed where they were).
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
//   drill      drill.depth_mm = −target.z (Z0 is the work surface; the depth is measured from
//              the touch point), through = false, wear ratio and Tdr of the active condition; XY
//              held by px/py; when the drill child is DONE (after its retract) a rapid takes the
//              electrode back to where the block began, so a drilling block ends at its start
//              point (the G-code interpreter's current point after it, docs/gcode.md).
//   orbit_finish  finish.final_offset_mm = final_radius_mm − orbit_radius_offset_mm (the
//              electrode radius plus the finishing side gap, calibrated: docs/blocks.md); Z held.
//   end        finishes the job.
// Soft limits: every cycle the actual X/Y/Z are compared with the config's axis limits; outside
// → alarm 141 (kSoftLimit, fault → safe state). A following-error fault of a loop → alarm 140.
//
// Outputs for the I/O image: vx/vy/vz_cmd_mm_s, gen_arm, gen_on, polarity_positive,
// on_time_us, off_time_us, servo_ref_v, flushing_on, rotation_on; progress: state, block_index,
// line, jobs_finished.
// Job figures (reset when a job begins, frozen when it ends; the HMI's job report reads them, so
// they survive the HMI): job_time_s (machine time in the job), job_pulses / job_shorts / job_arcs
// (the I/O counts n_open + n_normal + n_transient_arc + n_stable_arc + n_short, n_short, and
// n_transient_arc + n_stable_arc summed over the job's cycles; unwired count inputs read 0),
// job_depth_mm (deepest depth_reached_mm of the job's drilling blocks), job_wear_mm (estimated
// electrode wear, eq. 8, summed over the drilling blocks).
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
#include "edm/programs/wall_finish.hpp"
#include "edm/runtime/block.hpp"
#include "edm/runtime/composite_block.hpp"
#include "edm/runtime/job.hpp"

namespace edm::programs {

struct EdmJobParams {
  double rapid_speed_mm_s{10.0};          // [mm/s] > 0
  double feed_default_mm_s{2.0};          // [mm/s] > 0, linear/arc feed when the block has none
  double orbit_radius_offset_mm{0.5525};  // [mm] > 0, electrode radius + finishing side gap
  rt::Duration polarity_settle{std::chrono::milliseconds(20)};  // ≥ 0
  double kv{20.0};                                              // [1/s] > 0 → px, py, pz
  double f_err_max_mm{1.0};                                     // [mm] > 0 → px, py, pz

  void visit(rt::ParamVisitor& v);
  [[nodiscard]] std::vector<rt::ParamError> validate() const;
};

class EdmJob final : public rt::BlockWithParams<EdmJobParams, rt::CompositeBlock> {
 public:
  enum class State : std::int64_t { kIdle = 0, kRun = 1 };

  EdmJob();
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 protected:
  void visit_own_pins(rt::PinVisitor& v) override;
  std::vector<rt::ParamError> configure_self(const rt::BlockSetup& setup) override;
  void activate_self() noexcept override;
  void safe_state_self(const rt::SafeStateRequest& request) noexcept override;
  void params_changed() noexcept override;

 private:
  enum class Step : std::uint8_t { kEnter, kLoad, kGo, kBusy, kSettle };

  void finish_job(rt::JobOutcome outcome) noexcept;
  void begin_job_figures(const rt::CycleContext& ctx) noexcept;
  void count_job_figures(const rt::CycleContext& ctx) noexcept;
  void select_condition(int e) noexcept;
  /// Executes the current block one cycle; true when it is complete.
  bool run_block(const machining::MotionBlock& b, const rt::CycleContext& ctx, bool hold,
                 rt::BlockStatus& status) noexcept;
  void hold_position() noexcept;
  void stop_outputs() noexcept;
  [[nodiscard]] bool in_position() const noexcept;

  DeepHoleDrill& drill_;
  WallFinish& finish_;
  blocks::LinearInterpolator& lin_;
  blocks::CircularInterpolator& arc_;
  blocks::PositionLoop& px_;
  blocks::PositionLoop& py_;
  blocks::PositionLoop& pz_;

  rt::Machine* machine_{nullptr};
  rt::JobStore* job_{nullptr};
  const machining::MachineTables* tables_{nullptr};
  const char* name_{""};

  // Own pins.
  rt::Input<std::int64_t> td_sum_ns_, td_count_, n_open_, n_short_;
  rt::Input<std::int64_t> n_normal_, n_transient_arc_, n_stable_arc_;
  rt::Input<double> x_mm_, y_mm_, z_mm_;
  rt::Output<double> vx_, vy_, vz_;
  rt::Output<bool> gen_arm_, gen_on_, polarity_positive_, flushing_on_, rotation_on_;
  rt::Output<double> on_time_us_, off_time_us_, servo_ref_v_;
  rt::Output<std::int64_t> state_, block_index_, line_, jobs_finished_;
  rt::Output<double> job_time_s_, job_depth_mm_, job_wear_mm_;
  rt::Output<std::int64_t> job_pulses_, job_shorts_, job_arcs_;

  // Cells the children's inputs are wired to.
  rt::Output<std::int64_t> c_td_sum_ns_, c_td_count_, c_n_open_, c_n_short_;
  rt::Output<double> c_x_, c_y_, c_z_;
  rt::Output<bool> c_drill_start_, c_finish_start_, c_through_, c_hold_;
  rt::Output<double> c_depth_, c_wear_ratio_, c_tdr_, c_final_offset_, c_start_offset_;
  rt::Output<bool> c_lin_start_, c_lin_hold_, c_lin_load_;
  rt::Output<double> c_lx_, c_ly_, c_lz_, c_lin_feed_;
  rt::Output<bool> c_arc_start_, c_arc_hold_, c_arc_load_, c_arc_cw_, c_arc_full_;
  rt::Output<double> c_i_, c_j_, c_ex_, c_ey_, c_arc_feed_;
  rt::Output<std::int64_t> c_turns_;
  rt::Output<double> c_xref_, c_yref_, c_zref_, c_vffx_, c_vffy_, c_vffz_;
  rt::Output<bool> c_loop_enable_;
  // Children's outputs.
  const rt::Output<double>*drill_vz_{}, *finish_vx_{}, *finish_vy_{};
  const rt::Output<bool>*drill_gen_{}, *finish_gen_{}, *finish_pos_{};
  const rt::Output<std::int64_t>*drill_state_{}, *finish_state_{};
  const rt::Output<double>*drill_depth_{}, *drill_wear_{};
  const rt::Output<double>*lin_rx_{}, *lin_ry_{}, *lin_rz_{}, *lin_vx_{}, *lin_vy_{}, *lin_vz_{};
  const rt::Output<bool>* lin_done_{};
  const rt::Output<double>*arc_rx_{}, *arc_ry_{}, *arc_vx_{}, *arc_vy_{};
  const rt::Output<bool>* arc_done_{};
  const rt::Output<double>*px_v_{}, *py_v_{}, *pz_v_{};
  const rt::Output<bool>*px_inpos_{}, *py_inpos_{}, *pz_inpos_{};
  const rt::Output<bool>*px_ferr_{}, *py_ferr_{}, *pz_ferr_{};

  State state_value_{State::kIdle};
  Step step_{Step::kEnter};
  double hold_x_{0.0}, hold_y_{0.0}, hold_z_{0.0};  // references while no move is interpolated
  bool hold_valid_{false};  // hold_* are set (false after activation and in a safe state)
  rt::TimePoint wait_until_{};
  const machining::Condition* condition_{nullptr};
  bool polarity_positive_value_{false};
  bool limit_alarm_raised_{false};
  rt::TimePoint job_start_{};
  double wear_before_block_{0.0};  // job_wear_mm when the current drilling block began
  bool drill_returning_{false};    // the drill is done; rapid back to the block's start
  machining::MotionBlock drill_return_{};
};

}  // namespace edm::programs
