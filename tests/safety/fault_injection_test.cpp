// Fault injection on the shipped simulated machines (DESIGN §11, issue 19 item 6): each test
// injects one fault and asserts the machine state, the outputs (generator, axis commands) and
// the alarm code within a stated number of 1 ms cycles. docs/safety.md lists them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "safety/safety_rig.hpp"

namespace edm::test {
namespace {

using rt::AlarmCode;
using rt::MachineState;

// A runtime command beyond the soft limits is refused: the operator forces Z down at full speed
// on the sinking machine (whose servo has no position loop to object); the supervisor cuts it
// where Z can still stop above Z min (-60 mm), faults (141) in that cycle, and Z stops inside
// its range. The generator is disarmed: with it sparking, the short at the work would stop the
// feed there first (the short stop, short_stop_test.cpp), and the simulator models no collision.
TEST(FaultInjection, RuntimeCommandBeyondTheSoftLimitIsRefused) {
  SafetyRig m(shipped_config("sink-sim"), "sink-sim.yaml");
  m.run_ms(20);
  ASSERT_TRUE(m.vars().force("io.gen_arm", 0.0));
  ASSERT_TRUE(m.vars().force("io.vz_cmd", -30.0));
  double z_min_seen = 0.0;
  const int n = m.step_until(
      [&] {
        z_min_seen = std::min(z_min_seen, m.read("io.z_mm"));
        return m.read("io.vz_cmd") != -30.0;
      },
      3000);
  ASSERT_LE(n, 3000);
  EXPECT_EQ(m.state(), MachineState::kFault) << "in the cycle of the refusal";
  EXPECT_EQ(m.machine().last_cause(), AlarmCode::kSoftLimit);
  ASSERT_EQ(m.alarms(AlarmCode::kSoftLimit), 1u);
  EXPECT_EQ(m.seen.back().source, std::string("safety.Z"));
  EXPECT_EQ(m.read("io.vz_cmd"), 0.0) << "the forced -30 mm/s is not what the drive gets";
  EXPECT_EQ(m.read("io.gen_on"), 0.0) << "generator off in the same cycle";
  EXPECT_GT(m.read("io.z_mm"), -60.0 + 0.2) << "refused at the braking distance, not before";
  EXPECT_LT(m.read("io.z_mm"), -60.0 + 0.3);
  for (int k = 0; k < 200; ++k) {
    m.step();
    z_min_seen = std::min(z_min_seen, m.read("io.z_mm"));
  }
  // The command stops Z at the limit; the simulated drive (ω_n 200 rad/s, ζ 0.55) overshoots a
  // stop from 30 mm/s by 26 µm, inside the following-error band (min_ferror_mm 0.1).
  EXPECT_GE(z_min_seen, -60.0 - 0.03) << "Z crossed its soft limit by more than the overshoot";
}

// A forced velocity, then FAULT: the axes stop. The force is released by the runtime and the
// supervisor holds the command at 0 in the same cycle; X decelerates at a_max and stays.
TEST(FaultInjection, ForcedVelocityThenFaultStopsTheAxes) {
  SafetyRig m(shipped_config("drill-sim"));
  m.run_ms(20);
  ASSERT_TRUE(m.vars().force("io.vx_cmd", 30.0));
  m.run_ms(30);
  ASSERT_EQ(m.read("io.vx_cmd"), 30.0);
  rt::Alarm fault;
  fault.code = AlarmCode::kBlockFault;
  fault.source = "test";
  fault.text = "injected fault";
  m.machine().raise(fault);
  m.step();
  EXPECT_EQ(m.state(), MachineState::kFault);
  EXPECT_EQ(m.read("io.vx_cmd"), 0.0) << "within 1 cycle";
  EXPECT_EQ(m.read("io.vy_cmd"), 0.0);
  EXPECT_GE(m.read("io.vz_cmd"), 0.0) << "Z: at most its back-off";
  EXPECT_EQ(m.read("io.gen_on"), 0.0);
  m.run_ms(50);  // 30 mm/s at 2000 mm/s² stops within 0.25 mm, in 15 ms
  const double x_stopped = m.read("io.x_mm");
  m.run_ms(500);
  EXPECT_NEAR(m.read("io.x_mm"), x_stopped, 1e-3);
}

// An electrode near its end: the drill preset's tube made 5.3 mm long, the margin is 5 mm.
// DeepHoleDrill drills at the first scan; alarm 160 and the safe state come in the cycle the
// length reads <= 5 mm, long before the holder (length 0), and Z backs off.
TEST(FaultInjection, ElectrodeNearItsEndRaises160BeforeTheHolder) {
  SafetyRig m(edited(shipped_config("drill-sim-program"), "params: {preset: drill, seed: 1}",
                     "params: {preset: drill, seed: 1, electrode_length_mm: 5.3}"),
              "drill-sim-program.yaml");
  double left = 0.0;
  double gen_before = 0.0;
  const int n = m.step_until(
      [&] {
        left = m.read("io.electrode_mm");
        const bool fault = m.state() == MachineState::kFault;
        if (!fault) gen_before = m.read("io.gen_on");
        return fault;
      },
      60000);
  ASSERT_LE(n, 60000) << "never used up (electrode " << left << " mm)";
  EXPECT_EQ(m.machine().last_cause(), AlarmCode::kElectrodeUsedUp);
  EXPECT_EQ(m.alarms(AlarmCode::kElectrodeUsedUp), 1u);
  EXPECT_LE(left, 5.0) << "raised in the cycle the length reached the margin";
  EXPECT_GT(left, 4.99) << "not later";
  EXPECT_EQ(gen_before, 1.0) << "it was drilling";
  EXPECT_EQ(m.read("io.gen_on"), 0.0) << "generator off in the same cycle";
  EXPECT_GE(m.read("io.vz_cmd"), 0.0) << "no feed toward the work";
  const double z0 = m.read("io.z_mm");
  m.run_ms(500);
  EXPECT_GT(m.read("io.z_mm"), z0 + 0.5) << "Z backs off in FAULT (retract: positive)";
  EXPECT_GT(m.read("io.electrode_mm"), 4.99) << "no more wear: the holder is never reached";
}

// A wire break (the wire-break input of the process image turns true): alarm 170, FAULT, the
// axis command 0 and the generator off, within 1 cycle of the driver publishing it.
TEST(FaultInjection, WireBreakRaises170AndTheSafeState) {
  SafetyRig m(shipped_config("wire-process-sim"), "wire-process-sim.yaml");
  m.run_ms(200);
  ASSERT_EQ(m.state(), MachineState::kReady);
  ASSERT_NE(m.read("io.vz_cmd"), 0.0) << "the servo is feeding";
  ASSERT_TRUE(m.vars().force("io.wire_broken", 1.0));  // the driver's next latch publishes it
  m.step();
  EXPECT_EQ(m.state(), MachineState::kFault);
  EXPECT_EQ(m.machine().last_cause(), AlarmCode::kWireBreak);
  EXPECT_EQ(m.alarms(AlarmCode::kWireBreak), 1u);
  EXPECT_EQ(m.seen.back().source, std::string("safety.wire"));
  EXPECT_EQ(m.read("io.vz_cmd"), 0.0);
  EXPECT_EQ(m.read("io.gen_on"), 0.0);
  m.run_ms(100);
  EXPECT_EQ(m.alarms(AlarmCode::kWireBreak), 1u) << "one alarm per occurrence";
}

// A jammed axis on the whole machine: X's encoder stops (io.x_mm forced to where it is) while
// X is commanded at 10 mm/s — a following error within 45 cycles (limit 0.4 mm at 10 mm/s).
TEST(FaultInjection, JammedAxisOnTheDrillGivesAFollowingError) {
  SafetyRig m(shipped_config("drill-sim"));
  m.run_ms(20);
  ASSERT_TRUE(m.vars().force("io.vx_cmd", 10.0));
  m.run_ms(100);
  ASSERT_EQ(m.state(), MachineState::kReady) << "a moving axis is followed";
  ASSERT_TRUE(m.vars().force("io.x_mm", m.read("io.x_mm")));
  const int n = m.step_until([&] { return m.state() == MachineState::kFault; }, 200);
  EXPECT_LE(n, 45);
  EXPECT_EQ(m.machine().last_cause(), AlarmCode::kFollowingError);
  EXPECT_EQ(m.alarms(AlarmCode::kFollowingError), 1u);
  EXPECT_EQ(m.read("io.vx_cmd"), 0.0);
  EXPECT_EQ(m.read("io.gen_on"), 0.0);
}

}  // namespace
}  // namespace edm::test
