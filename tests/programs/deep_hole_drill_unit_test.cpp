// DeepHoleDrill sequence on synthetic inputs: touch detection, retract at depth, safe state.

#include <gtest/gtest.h>

#include <chrono>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include "drill_rig.hpp"
#include "edm/programs/deep_hole_drill.hpp"
#include "edm/programs/register.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;
using programs::DeepHoleDrill;

programs::DeepHoleDrillParams unit_params() {
  programs::DeepHoleDrillParams p;
  p.depth_default_mm = 2.0;
  p.touch_cycles = 3;
  p.clearance_mm = 1.0;
  return p;
}

TEST(DeepHoleDrill, RegisteredAsAProgramType) { EXPECT_TRUE(is_builtin_program("DeepHoleDrill")); }

TEST(DeepHoleDrill, IdleUntilARisingStartThenApproachesWithTheGeneratorOn) {
  Rig r(unit_params());
  r.step();
  EXPECT_EQ(r.state(), 0);
  EXPECT_FALSE(r.gen());
  EXPECT_EQ(r.vz(), 0.0);
  r.start.set(true);
  r.step();
  EXPECT_EQ(r.state(), 1);
  EXPECT_TRUE(r.gen());
  EXPECT_DOUBLE_EQ(r.vz(), -0.5);
}

// The operator's feed override (EdmJob wires it): it scales the approach and caps the downward
// feed of DRILL at override·v_feed_max; backing off is never scaled; not finite: no feed.
TEST(DeepHoleDrill, FeedOverrideScalesTheApproachAndTheDownwardCapNeverTheBackOff) {
  Rig r(unit_params());
  rt::Output<double> ov;
  ov.set(0.5);
  r.in<double>("feed_override").connect(ov);
  r.comp.set(false);
  r.start.set(true);
  r.z_mm.set(0.0);
  r.step();
  EXPECT_DOUBLE_EQ(r.vz(), -0.5 * 0.5) << "the approach at half speed";
  r.sparks(20, 100.0);  // a wide gap: the P law asks for its full 1 mm/s down
  for (int k = 0; k < 4; ++k) r.step();
  ASSERT_EQ(r.state(), 2);
  r.step();
  EXPECT_DOUBLE_EQ(r.vz(), -1.0 * 0.5) << "capped at override x v_feed_max";
  ov.set(0.0);
  r.step();
  EXPECT_DOUBLE_EQ(r.vz(), 0.0) << "0 %: no feed";
  r.sparks(20, 4.0);  // too small a gap: back off, whatever the override
  for (int k = 0; k < 10; ++k) r.step();
  EXPECT_NEAR(r.vz(), +0.05 * 4.0, 1e-9);
  ov.set(std::numeric_limits<double>::quiet_NaN());
  r.sparks(20, 100.0);
  for (int k = 0; k < 10; ++k) r.step();
  EXPECT_DOUBLE_EQ(r.vz(), 0.0) << "a broken override feeds nothing";
}

TEST(DeepHoleDrill, TouchNeedsTouchCyclesConsecutiveCyclesWithSparks) {
  Rig r(unit_params());
  r.start.set(true);
  r.z_mm.set(0.1);
  r.step();  // APPROACH
  r.sparks(5, 8.0);
  r.step();
  r.step();
  r.sparks(0, 0.0);  // a lone pair of sparks is not a touch
  r.step();
  EXPECT_EQ(r.state(), 1);
  r.sparks(5, 8.0);
  r.step();
  r.step();
  EXPECT_EQ(r.state(), 1);
  r.z_mm.set(0.03);
  r.step();  // third consecutive cycle
  EXPECT_EQ(r.state(), 2);
  EXPECT_DOUBLE_EQ(r.out<double>("touch_z_mm"), 0.03);
  EXPECT_TRUE(r.gen());
}

TEST(DeepHoleDrill, DrillsOnTdThenRetractsAtDepthAndEndsDone) {
  auto p = unit_params();
  Rig r(p);
  r.comp.set(false);  // depth = touch_z − z exactly
  r.start.set(true);
  r.z_mm.set(0.0);
  r.sparks(20, 12.0);  // Td > Tdr (8 µs): the gap is too large → feed down
  for (int k = 0; k < 4; ++k) r.step();
  ASSERT_EQ(r.state(), 2);
  r.step();
  EXPECT_LT(r.vz(), 0.0);
  EXPECT_NEAR(r.vz(), -0.05 * (12.0 - 8.0), 1e-9);  // Kg·(Tdr − Td)
  r.sparks(20, 4.0);                                // too small → back off
  for (int k = 0; k < 10; ++k) r.step();
  EXPECT_NEAR(r.vz(), +0.05 * 4.0, 1e-9);
  r.z_mm.set(-1.999);
  r.step();
  EXPECT_EQ(r.state(), 2);
  EXPECT_NEAR(r.out<double>("depth_reached_mm"), 1.999, 1e-12);
  r.z_mm.set(-2.0);
  r.step();
  EXPECT_EQ(r.state(), 3);
  EXPECT_FALSE(r.gen());
  EXPECT_DOUBLE_EQ(r.vz(), 5.0);
  r.z_mm.set(0.5);
  r.step();
  EXPECT_EQ(r.state(), 3);  // back to touch_z + clearance = 1.0
  r.z_mm.set(1.0);
  r.step();
  EXPECT_EQ(r.state(), 4);
  EXPECT_TRUE(r.out<bool>("done"));
  EXPECT_EQ(r.vz(), 0.0);
  EXPECT_FALSE(r.gen());
  r.step();  // start still true: no new edge, stays DONE
  EXPECT_EQ(r.state(), 4);
}

TEST(DeepHoleDrill, WearCompensationFeedsFasterAndIsSubtractedFromTheDepth) {
  Rig r(unit_params());
  r.start_sparking(20, 12.0, 20);
  ASSERT_EQ(r.state(), 2);
  const double vz_in = -0.05 * 4.0;
  const double area = (1.1 * 1.1) / (1.0 - 0.09);
  EXPECT_NEAR(r.vz(), vz_in - 0.6 * area * 0.2, 1e-9);  // vz_in − Vd
  r.z_mm.set(-2.0);
  r.step();
  EXPECT_EQ(r.state(), 2) << "wear makes the front shallower than the axis";
  EXPECT_LT(r.out<double>("depth_reached_mm"), 2.0);
  EXPECT_GT(r.out<double>("depth_reached_mm"), 1.95);
}

// A wired vz_servo_mm_s replaces the P law in DRILL (clamped to the gap child's −1 … +5 mm/s),
// passes through the same wear compensation, and a broken (non-finite) value stops the feed.
TEST(DeepHoleDrill, AWiredExternalServoReplacesThePLawInDrill) {
  Rig r(unit_params());
  rt::Output<double> servo;
  r.wire_servo(servo);
  r.comp.set(false);
  servo.set(-0.3);                // the external servo says −0.3 mm/s,
  r.start_sparking(20, 12.0, 2);  // the P law −0.2 mm/s
  ASSERT_EQ(r.state(), 1) << "approach is the sequence's own: the servo is not used";
  EXPECT_DOUBLE_EQ(r.vz(), -0.5);
  r.step();  // the third cycle with sparks: touch, and the first DRILL cycle
  ASSERT_EQ(r.state(), 2);
  EXPECT_DOUBLE_EQ(r.vz(), -0.3);
  r.step();
  EXPECT_NEAR(r.out<double>("gap.vz_mm_s"), -0.2, 1e-9) << "the P law still runs, observable";
  servo.set(+0.7);  // back off
  r.step();
  EXPECT_DOUBLE_EQ(r.vz(), +0.7);
  for (const auto& [cmd, want] : {std::pair{-3.0, -1.0}, std::pair{9.0, 5.0}}) {
    servo.set(cmd);
    EXPECT_EQ(r.drill.update(r.ctx), rt::BlockStatus::kOk);
    EXPECT_DOUBLE_EQ(r.vz(), want) << "clamped to the gap child's limits";
  }
  servo.set(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(r.drill.update(r.ctx), rt::BlockStatus::kFault);
  EXPECT_DOUBLE_EQ(r.vz(), 0.0) << "a broken servo signal stops the feed";
  EXPECT_EQ(r.state(), 2);
}

TEST(DeepHoleDrill, WearCompensationActsOnTheExternalServosCommand) {
  Rig r(unit_params());
  rt::Output<double> servo;
  r.wire_servo(servo);
  servo.set(-0.25);
  r.start_sparking(20, 12.0, 20);
  ASSERT_EQ(r.state(), 2);
  const double area = (1.1 * 1.1) / (1.0 - 0.09);
  EXPECT_NEAR(r.vz(), -0.25 - 0.6 * area * 0.25, 1e-9);  // vz_in − Vd, vz_in = the servo's
}

TEST(DeepHoleDrill, SafeStateTurnsTheGeneratorOffAndBacksZOffWithoutFinishing) {
  Rig r(unit_params());
  r.start_sparking(20, 12.0, 10);
  ASSERT_EQ(r.state(), 2);
  r.z_mm.set(-0.5);
  r.drill.enter_safe_state({rt::MachineState::kFault, rt::AlarmCode::kNone});
  EXPECT_FALSE(r.gen());
  EXPECT_EQ(r.state(), 3);
  EXPECT_DOUBLE_EQ(r.vz(), 5.0);
  r.ctx.state = rt::MachineState::kFault;
  r.step();
  EXPECT_EQ(r.state(), 3);
  EXPECT_FALSE(r.gen());
  EXPECT_DOUBLE_EQ(r.vz(), 5.0);
  r.z_mm.set(1.0);  // touch_z (0) + clearance
  r.step();
  EXPECT_EQ(r.state(), 0) << "an aborted hole is not DONE";
  EXPECT_FALSE(r.out<bool>("done"));
  EXPECT_EQ(r.vz(), 0.0);
  r.start.set(false);
  r.step();
  r.start.set(true);
  r.step();
  EXPECT_EQ(r.state(), 0) << "start is ignored in a safe state";
  r.ctx.state = rt::MachineState::kReady;
  r.start.set(false);
  r.step();
  r.start.set(true);
  r.step();
  EXPECT_EQ(r.state(), 1);
}

TEST(DeepHoleDrill, SafeStateDuringApproachBacksOffByTheClearance) {
  Rig r(unit_params());
  r.start.set(true);
  r.z_mm.set(0.2);
  r.step();
  ASSERT_EQ(r.state(), 1);
  r.drill.enter_safe_state({rt::MachineState::kEstop, rt::AlarmCode::kNone});
  EXPECT_EQ(r.state(), 3);
  EXPECT_FALSE(r.gen());
  r.ctx.state = rt::MachineState::kEstop;
  r.z_mm.set(1.2);
  r.step();
  EXPECT_EQ(r.state(), 0);
}

TEST(DeepHoleDrill, BadParametersAreRefused) {
  auto p = unit_params();
  p.depth_default_mm = 0.0;
  p.touch_cycles = 0;
  p.approach_speed_mm_s = 2.0;
  DeepHoleDrill d;
  d.set_params(p);
  EXPECT_EQ(d.validate().size(), 3u);
}

}  // namespace
}  // namespace edm::test
