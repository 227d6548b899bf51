// AxisArbiter (issue 32): who commands each axis, per axis, over every combination of the
// machine's state, manual motion and a cycle's claim.

#include "edm/programs/axis_arbiter.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace edm::test {
namespace {

using programs::AxisArbiter;

struct ArbiterRig {
  AxisArbiter a;
  rt::Output<bool> manual;
  rt::Output<double> man_v{-1.0}, loop_v{-2.0};
  ArbiterRig() {
    a.manual.connect(manual);
    for (rt::Input<double>& in : a.manual_v) in.connect(man_v);
    for (rt::Input<double>& in : a.loop_v) in.connect(loop_v);
    for (rt::Input<bool>& in : a.cycle) in.claim();
    a.cycle_v.x().claim(-3.0);
    a.cycle_v.y().claim(-4.0);
    a.cycle_v.z().claim(-5.0);
    a.activate();
  }
};

TEST(AxisArbiter, EachAxisFollowsTheSafeStateThenManualThenItsCycleThenItsLoop) {
  for (const rt::MachineState state :
       {rt::MachineState::kReady, rt::MachineState::kRunning, rt::MachineState::kHold,
        rt::MachineState::kFault, rt::MachineState::kEstop}) {
    for (int mask = 0; mask < 16; ++mask) {  // bit 0: manual, bits 1-3: cycle claims x, y, z
      ArbiterRig r;
      const bool manual = (mask & 1) != 0;
      const bool claims[3] = {(mask & 2) != 0, (mask & 4) != 0, (mask & 8) != 0};
      r.manual.set(manual);
      for (std::size_t k = 0; k < 3; ++k) r.a.cycle[k].drive(claims[k]);
      rt::CycleContext ctx;
      ctx.state = state;
      ASSERT_EQ(r.a.update(ctx), rt::BlockStatus::kOk);
      const bool safe = rt::is_safe_state(state);
      const double cycle_v[3] = {-3.0, -4.0, -5.0};
      for (std::size_t k = 0; k < 3; ++k) {
        std::int64_t want = AxisArbiter::kMove;
        double v = -2.0;
        if (safe) {
          want = claims[k] ? AxisArbiter::kCycle : AxisArbiter::kStopped;
          v = claims[k] ? cycle_v[k] : 0.0;
        } else if (manual) {
          want = AxisArbiter::kManual;
          v = -1.0;
        } else if (claims[k]) {
          want = AxisArbiter::kCycle;
          v = cycle_v[k];
        }
        EXPECT_EQ(r.a.owner[k].get(), want)
            << "state " << static_cast<int>(state) << " mask " << mask << " axis " << k;
        EXPECT_EQ(r.a.v_cmd[k].get(), v)
            << "state " << static_cast<int>(state) << " mask " << mask << " axis " << k;
      }
    }
  }
}

TEST(AxisArbiter, TheSafeStateStopsEveryAxisAtOnce) {
  ArbiterRig r;
  rt::CycleContext ctx;
  ctx.state = rt::MachineState::kRunning;
  r.a.update(ctx);
  ASSERT_EQ(r.a.v_cmd.z().get(), -2.0);
  r.a.enter_safe_state({rt::MachineState::kEstop, rt::AlarmCode::kNone});
  for (const rt::Output<double>& v : r.a.v_cmd) EXPECT_EQ(v.get(), 0.0);
  for (const rt::Output<std::int64_t>& o : r.a.owner) EXPECT_EQ(o.get(), AxisArbiter::kStopped);
}

}  // namespace
}  // namespace edm::test
