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
// Outputs owner_x/y/z show the decision. The pins are axis triples (rt::Xyz, xyz_pins.hpp). RT-safe
// update(); no parameters.

#include <cstdint>

#include "edm/runtime/block.hpp"
#include "edm/runtime/xyz_pins.hpp"

namespace edm::programs {

class AxisArbiter final : public rt::Block {
 public:
  enum Owner : std::int64_t { kMove = 0, kCycle = 1, kManual = 2, kStopped = 3 };

  rt::Input<bool> manual{pins_, "manual"};
  rt::Xyz<rt::Input<double>> manual_v{
      pins_, {"manual_vx_mm_s", "manual_vy_mm_s", "manual_vz_mm_s"}, "mm/s"};
  rt::Xyz<rt::Input<bool>> cycle{pins_, {"cycle_x", "cycle_y", "cycle_z"}};
  rt::Xyz<rt::Input<double>> cycle_v{
      pins_, {"cycle_vx_mm_s", "cycle_vy_mm_s", "cycle_vz_mm_s"}, "mm/s"};
  rt::Xyz<rt::Input<double>> loop_v{
      pins_, {"loop_vx_mm_s", "loop_vy_mm_s", "loop_vz_mm_s"}, "mm/s"};
  rt::Xyz<rt::Output<double>> v_cmd{pins_, {"vx_cmd_mm_s", "vy_cmd_mm_s", "vz_cmd_mm_s"}, "mm/s"};
  rt::Xyz<rt::Output<std::int64_t>> owner{pins_, {"owner_x", "owner_y", "owner_z"}};

  void activate() noexcept override;
  void enter_safe_state(const rt::SafeStateRequest& request) noexcept override;
  rt::BlockStatus update(const rt::CycleContext& ctx) noexcept override;
};

}  // namespace edm::programs
