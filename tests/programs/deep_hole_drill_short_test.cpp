// DeepHoleDrill and short circuits (issue 19), on synthetic pulse counts with a contact model:
// gap truth (a short-dominated window backs off), the retract along the drilled path and its
// resume, alarm 150 after N retracts within the window, and — asserted on every cycle — no feed
// toward the work while the gap reads short.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "drill_rig.hpp"
#include "support/param_access.hpp"

namespace edm::test {
namespace {

constexpr double kClearMm = 0.02;  // the contact clears once the tip is this far above it

programs::DeepHoleDrillParams params() {
  programs::DeepHoleDrillParams p;
  p.depth_default_mm = 2.0;
  return p;
}

// One cycle: 20 pulses, all shorts while the tip is within kClearMm of the contact at
// `contact_z` (not above it), else sparks at Td = 12 µs (the P law feeds down at 0.2 mm/s); the
// axis follows the command exactly. Checks the no-feed-while-short invariant.
struct ContactRun {
  Rig rig{params()};
  double contact_z{-1e9};
  bool cleared{false};
  bool persistent{false};
  std::int64_t cycles{0};
  std::int64_t first_short_cycle{-1};  // the detection: retract.short_cycles cycles reading short
  std::int64_t run_length{0};
  std::int64_t first_retract_cycle{-1};
  std::int64_t fault_cycles{0};  // cycles whose update() returned kFault

  std::int64_t short_cycles{rig.drill.read_param(param_index(rig.drill, "retract.short_cycles")).i};

  ContactRun() {
    rig.comp.set(false);
    rig.start.set(true);
  }
  bool in_contact() const {
    const bool touching = rig.z_mm.get() <= contact_z + kClearMm;
    return touching && (persistent || !cleared);
  }
  void cycle() {
    if (in_contact()) {
      rig.sparks(0, 0.0);
      rig.n_short.set(20);
    } else {
      if (rig.z_mm.get() > contact_z + kClearMm && contact_z > -1e8) {
        cleared = true;
      }
      rig.sparks(20, 12.0);
      rig.n_short.set(0);
    }
    rig.step();
    if (rig.last == rt::BlockStatus::kFault) ++fault_cycles;
    rig.ctx.release += 1ms;
    const bool reads_short = rig.out<bool>("short_now");  // the window or the cycle
    if (reads_short) {
      EXPECT_GE(rig.vz(), 0.0) << "fed toward the work while the gap reads short, cycle " << cycles;
      if (++run_length == short_cycles && first_short_cycle < 0) first_short_cycle = cycles;
    } else {
      run_length = 0;
    }
    if (rig.out<bool>("retract.active") && first_retract_cycle < 0) {
      first_retract_cycle = cycles;
    }
    rig.z_mm.set(rig.z_mm.get() + rig.vz() * 0.001);
    ++cycles;
  }
};

TEST(DeepHoleDrillShort, AShortOnlyWindowReadsTdZeroAndBacksOff) {
  ContactRun run;
  for (int k = 0; k < 200; ++k) run.cycle();
  ASSERT_EQ(run.rig.state(), 2);
  EXPECT_LT(run.rig.vz(), 0.0) << "drilling: feeding down";
  run.contact_z = run.rig.z_mm.get();  // a chip right under the tip
  run.cycle();
  EXPECT_NEAR(run.rig.out<double>("td.td_raw_us"), 0.0, 1e-12) << "a short counts as Td = 0";
  EXPECT_TRUE(run.rig.out<bool>("td.valid")) << "a window with shorts is a measurement";
  EXPECT_GT(run.rig.out<double>("gap.vz_mm_s"), run.rig.vz() - 1.0);
}

TEST(DeepHoleDrillShort, ATransientContactRetractsAlongThePathResumesAndReachesTheDepth) {
  ContactRun run;
  for (int k = 0; k < 300; ++k) run.cycle();
  ASSERT_EQ(run.rig.state(), 2);
  run.contact_z = run.rig.z_mm.get() - 0.005;
  for (int k = 0; k < 30000 && run.rig.state() == 2; ++k) run.cycle();
  ASSERT_GE(run.first_short_cycle, 0) << "the contact was met";
  ASSERT_GE(run.first_retract_cycle, 0);
  EXPECT_LE(run.first_retract_cycle - run.first_short_cycle, 2)
      << "the retract starts within 2 cycles of the detection";
  EXPECT_TRUE(run.cleared);
  EXPECT_EQ(run.rig.out<std::int64_t>("short_retracts"), 1);
  EXPECT_GT(run.rig.out<double>("short_time_s"), 0.0);
  EXPECT_EQ(run.rig.state(), 3) << "the hole reached its depth and retracts out";
  EXPECT_GE(run.rig.out<double>("depth_reached_mm"), 2.0);
}

TEST(DeepHoleDrillShort, APersistentContactGivesNRetractsThenHoldsBackedOff) {
  ContactRun run;
  run.persistent = true;
  for (int k = 0; k < 300; ++k) run.cycle();
  ASSERT_EQ(run.rig.state(), 2);
  run.contact_z = run.rig.z_mm.get() - 0.005;
  const auto n = run.rig.drill.params().shorts.short_retracts_max;
  double z_alarm = 0.0;
  for (int k = 0; k < 60000 && run.rig.state() == 2; ++k) {
    z_alarm = run.rig.z_mm.get();
    run.cycle();
  }
  EXPECT_EQ(run.rig.out<std::int64_t>("short_retracts"), n) << "exactly N retracts";
  EXPECT_EQ(run.rig.state(), 3) << "backing off";
  // Without a machine to raise alarm 150 on, the cycle that spends the budget reports a fault
  // (ShortGuard::step, as WallFinish does: the two no longer differ).
  EXPECT_EQ(run.fault_cycles, 1);
  EXPECT_FALSE(run.rig.gen());
  for (int k = 0; k < 2000 && run.rig.state() == 3; ++k) run.cycle();
  EXPECT_EQ(run.rig.state(), 0) << "holds (IDLE) after the back-off, the hole not done";
  EXPECT_FALSE(run.rig.out<bool>("done"));
  EXPECT_NEAR(run.rig.z_mm.get(), z_alarm + run.rig.drill.params().short_backoff_mm, 0.01);
  EXPECT_EQ(run.rig.vz(), 0.0);
  EXPECT_FALSE(run.rig.gen());
}

}  // namespace
}  // namespace edm::test
