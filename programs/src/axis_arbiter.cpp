#include "edm/programs/axis_arbiter.hpp"

namespace edm::programs {

void AxisArbiter::activate() noexcept {
  for (std::size_t a = 0; a < rt::kAxes; ++a) {
    v_cmd[a].set(0.0);
    owner[a].set(kMove);
  }
}

void AxisArbiter::enter_safe_state(const rt::SafeStateRequest& /*request*/) noexcept {
  // Until the next update() decides from the cycles' safe-state commands: nothing moves.
  for (std::size_t a = 0; a < rt::kAxes; ++a) {
    v_cmd[a].set(0.0);
    owner[a].set(kStopped);
  }
}

rt::BlockStatus AxisArbiter::update(const rt::CycleContext& ctx) noexcept {
  const bool safe = rt::is_safe_state(ctx.state);
  const bool manual_active = manual.get();
  for (std::size_t a = 0; a < rt::kAxes; ++a) {
    const bool claimed = cycle[a].get();
    const Owner o = safe            ? (claimed ? kCycle : kStopped)
                    : manual_active ? kManual
                    : claimed       ? kCycle
                                    : kMove;
    owner[a].set(o);
    v_cmd[a].set(o == kCycle    ? cycle_v[a].get()
                 : o == kManual ? manual_v[a].get()
                 : o == kMove   ? loop_v[a].get()
                                : 0.0);
  }
  return rt::BlockStatus::kOk;
}

}  // namespace edm::programs
