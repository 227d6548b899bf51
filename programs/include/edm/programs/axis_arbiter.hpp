#pragma once
// AxisArbiter: who commands each axis of a job, decided in one place (issue 32). A child of the
// job sequencer (EdmJob's `axes`); its outputs vx/vy/vz_cmd_mm_s are the job's axis commands,
// wired in YAML to the driver (`io.vx_cmd: job.axes.vx_cmd_mm_s`).
//
// Per axis, in this order:
//   safe state (FAULT, ESTOP)  the running machining cycle's command (its safe-state retract,
//                              e.g. the drill backing Z off), else 0: owner 3 (stopped);
//   manual                     ManualMotion moves the axes (reference, jog, touch-off): its
//                              command, owner 2;
//   cycle                      a machining cycle claims the axis (cycle_x/y/z: the drill Z, the
//                              orbit X and Y): its command, owner 1;
//   move                       else the position loop's, which follows the interpolated move or
//                              holds still: owner 0.
// Inputs: manual (manual.active) and manual_v*, loop_v* are connected to the children's outputs
// by the job; cycle_* are driven by the job from its running cycles (MachiningCycle::axes()).
// Outputs owner_x/y/z show the decision. RT-safe update(); no parameters.

#include <cstdint>

#include "edm/runtime/block.hpp"

namespace edm::programs {

class AxisArbiter final : public rt::Block {
 public:
  enum Owner : std::int64_t { kMove = 0, kCycle = 1, kManual = 2, kStopped = 3 };

  rt::Input<bool> manual{pins_, "manual"};
  rt::Input<double> manual_vx_mm_s{pins_, "manual_vx_mm_s", "mm/s"};
  rt::Input<double> manual_vy_mm_s{pins_, "manual_vy_mm_s", "mm/s"};
  rt::Input<double> manual_vz_mm_s{pins_, "manual_vz_mm_s", "mm/s"};
  rt::Input<bool> cycle_x{pins_, "cycle_x"};
  rt::Input<bool> cycle_y{pins_, "cycle_y"};
  rt::Input<bool> cycle_z{pins_, "cycle_z"};
  rt::Input<double> cycle_vx_mm_s{pins_, "cycle_vx_mm_s", "mm/s"};
  rt::Input<double> cycle_vy_mm_s{pins_, "cycle_vy_mm_s", "mm/s"};
  rt::Input<double> cycle_vz_mm_s{pins_, "cycle_vz_mm_s", "mm/s"};
  rt::Input<double> loop_vx_mm_s{pins_, "loop_vx_mm_s", "mm/s"};
  rt::Input<double> loop_vy_mm_s{pins_, "loop_vy_mm_s", "mm/s"};
  rt::Input<double> loop_vz_mm_s{pins_, "loop_vz_mm_s", "mm/s"};
  rt::Output<double> vx_cmd_mm_s{pins_, "vx_cmd_mm_s", "mm/s"};
  rt::Output<double> vy_cmd_mm_s{pins_, "vy_cmd_mm_s", "mm/s"};
  rt::Output<double> vz_cmd_mm_s{pins_, "vz_cmd_mm_s", "mm/s"};
  rt::Output<std::int64_t> owner_x{pins_, "owner_x"};
  rt::Output<std::int64_t> owner_y{pins_, "owner_y"};
  rt::Output<std::int64_t> owner_z{pins_, "owner_z"};

  void activate() noexcept override;
  void enter_safe_state(const rt::SafeStateRequest& request) noexcept override;
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;

 private:
  struct Axis {
    const rt::Input<bool>& cycle;
    const rt::Input<double>& cycle_v;
    const rt::Input<double>& manual_v;
    const rt::Input<double>& loop_v;
    rt::Output<double>& cmd;
    rt::Output<std::int64_t>& owner;
  };
  static void decide(const Axis& a, bool safe, bool manual_active) noexcept;
};

}  // namespace edm::programs
