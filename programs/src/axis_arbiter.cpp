#include "edm/programs/axis_arbiter.hpp"

namespace edm::programs {

void AxisArbiter::activate() noexcept {
  for (rt::Output<double>* v : {&vx_cmd_mm_s, &vy_cmd_mm_s, &vz_cmd_mm_s}) v->set(0.0);
  for (rt::Output<std::int64_t>* o : {&owner_x, &owner_y, &owner_z}) o->set(kMove);
}

void AxisArbiter::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  // Until the next update() decides from the cycles' safe-state commands: nothing moves.
  for (rt::Output<double>* v : {&vx_cmd_mm_s, &vy_cmd_mm_s, &vz_cmd_mm_s}) v->set(0.0);
  for (rt::Output<std::int64_t>* o : {&owner_x, &owner_y, &owner_z}) o->set(kStopped);
}

void AxisArbiter::decide(const Axis& a, bool safe, bool manual_active) noexcept {
  const bool cycle = a.cycle.get();
  const Owner o = safe            ? (cycle ? kCycle : kStopped)
                  : manual_active ? kManual
                  : cycle         ? kCycle
                                  : kMove;
  a.owner.set(o);
  a.cmd.set(o == kCycle    ? a.cycle_v.get()
            : o == kManual ? a.manual_v.get()
            : o == kMove   ? a.loop_v.get()
                           : 0.0);
}

rt::BlockStatus AxisArbiter::update(const rt::CycleContext& ctx) noexcept {
  const bool safe = rt::is_safe_state(ctx.state);
  const bool man = manual.get();
  decide({cycle_x, cycle_vx_mm_s, manual_vx_mm_s, loop_vx_mm_s, vx_cmd_mm_s, owner_x}, safe, man);
  decide({cycle_y, cycle_vy_mm_s, manual_vy_mm_s, loop_vy_mm_s, vy_cmd_mm_s, owner_y}, safe, man);
  decide({cycle_z, cycle_vz_mm_s, manual_vz_mm_s, loop_vz_mm_s, vz_cmd_mm_s, owner_z}, safe, man);
  return rt::BlockStatus::kOk;
}

}  // namespace edm::programs
