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
    for (rt::Input<double>* in : {&a.manual_vx_mm_s, &a.manual_vy_mm_s, &a.manual_vz_mm_s}) {
      in->connect(man_v);
    }
    for (rt::Input<double>* in : {&a.loop_vx_mm_s, &a.loop_vy_mm_s, &a.loop_vz_mm_s}) {
      in->connect(loop_v);
    }
    for (rt::Input<bool>* in : {&a.cycle_x, &a.cycle_y, &a.cycle_z}) in->claim();
    a.cycle_vx_mm_s.claim(-3.0);
    a.cycle_vy_mm_s.claim(-4.0);
    a.cycle_vz_mm_s.claim(-5.0);
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
      r.a.cycle_x.drive(claims[0]);
      r.a.cycle_y.drive(claims[1]);
      r.a.cycle_z.drive(claims[2]);
      rt::CycleContext ctx;
      ctx.state = state;
      ASSERT_EQ(r.a.update(ctx), rt::BlockStatus::kOk);
      const bool safe = rt::is_safe_state(state);
      const double cycle_v[3] = {-3.0, -4.0, -5.0};
      const rt::Output<double>* cmd[3] = {&r.a.vx_cmd_mm_s, &r.a.vy_cmd_mm_s, &r.a.vz_cmd_mm_s};
      const rt::Output<std::int64_t>* owner[3] = {&r.a.owner_x, &r.a.owner_y, &r.a.owner_z};
      for (int k = 0; k < 3; ++k) {
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
        EXPECT_EQ(owner[k]->get(), want)
            << "state " << static_cast<int>(state) << " mask " << mask << " axis " << k;
        EXPECT_EQ(cmd[k]->get(), v)
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
  ASSERT_EQ(r.a.vz_cmd_mm_s.get(), -2.0);
  r.a.enter_safe_state({rt::MachineState::kEstop, rt::AlarmCode::kNone});
  for (const rt::Output<double>* v : {&r.a.vx_cmd_mm_s, &r.a.vy_cmd_mm_s, &r.a.vz_cmd_mm_s}) {
    EXPECT_EQ(v->get(), 0.0);
  }
  EXPECT_EQ(r.a.owner_z.get(), AxisArbiter::kStopped);
}

}  // namespace
}  // namespace edm::test
