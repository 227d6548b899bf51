// The safety supervisor on a bench rig (loopback driver): one axis whose mechanics are a program
// — a drive (Gain, k = 0 jams it) and an Integrator — behind the loopback card. The command is a
// parameter written at run time (p.cmd.offset), the generator a constant-true BOOL output.
// Each test states the cycles within which the machine reacts (docs/safety.md).
#include <gtest/gtest.h>

#include <cmath>

#include "edm/runtime/supervisor.hpp"
#include "safety/safety_rig.hpp"

namespace edm::test {
namespace {

using rt::AlarmCode;
using rt::MachineState;

// io.ao0: X velocity command (mm/s) → io.ai0 next cycle → drive → axis → io.ao1 → io.ai1: X (mm).
constexpr const char* kRig = R"(version: 1
machine:
  name: rig
  io: {driver: loopback, params: {channels: 2}}
  axes:
    - {name: X, min_mm: -10, max_mm: 10, v_max_mm_s: 20, a_max_mm_s2: 10000}
  safety:
    axes:
      - {name: X, velocity: io.ao0, position: io.ai1, ferror_mm: 0.5, min_ferror_mm: 0.05}
    generator: [io.do0]
tasks:
  - name: io
    interval: 1ms
    priority: 0
    watchdog: {time: 1ms, sensitivity: 1, action: fault}
    programs: [p]
programs:
  - name: p
    blocks:
      # the command: its offset, written at run time
      - {name: cmd, type: Gain, params: {k: 0}}
      # the drive (k = 0 jams it) and the mechanics (x += v·dt)
      - {name: drive, type: Gain}
      - {name: axis, type: Integrator}
      # an injected slow block: cost_us of virtual time per cycle
      - {name: slow, type: Cost}
    wires:
      io.ao0: cmd.out
      io.do0: true
      drive.in: io.ai0
      axis.in: drive.out
      io.ao1: axis.out
)";

class SupervisorRig : public ::testing::Test {
 protected:
  SafetyRig rig{kRig};
  rt::LoopbackDriver& card() { return static_cast<rt::LoopbackDriver&>(rig.runtime->driver()); }
  void command(double v_mm_s) { ASSERT_TRUE(rig.vars().write("p.cmd.offset", v_mm_s)); }
  // The mechanics' position (io.ai1, the sensor, reads 0 in FAULT: the card's safe value).
  double x() { return rig.read("p.axis.out"); }
  double v_out() { return rig.read("io.ao0"); }
  bool generator() { return rig.read("io.do0") != 0.0; }
};

TEST_F(SupervisorRig, FollowsACommandedAxisWithoutAlarm) {
  command(15.0);
  rig.run_ms(300);
  EXPECT_EQ(rig.state(), MachineState::kReady);
  EXPECT_NEAR(x(), 15.0 * 0.298, 0.05);
  EXPECT_LT(rig.runtime->supervisor()->following_error_mm(0), 0.05);
  EXPECT_EQ(v_out(), 15.0);
  EXPECT_TRUE(generator());
  EXPECT_EQ(rig.alarms(AlarmCode::kFollowingError) + rig.alarms(AlarmCode::kSoftLimit), 0u);
}

// A runtime command beyond the soft limits is refused: cut to the speed from which the axis
// still stops at the limit, alarm 141 (fault) in the same cycle, and the safe state.
TEST_F(SupervisorRig, CommandBeyondTheSoftLimitIsRefusedInTheSameCycle) {
  command(20.0);
  const int n = rig.step_until([&] { return v_out() != 20.0; }, 1000);
  ASSERT_LE(n, 1000) << "never refused";
  EXPECT_EQ(rig.alarms(AlarmCode::kSoftLimit), 1u);
  EXPECT_EQ(rig.state(), MachineState::kFault);
  EXPECT_EQ(rig.machine().last_cause(), AlarmCode::kSoftLimit);
  EXPECT_EQ(v_out(), 0.0) << "refused and held at 0 in the cycle it was refused";
  EXPECT_FALSE(generator());
  EXPECT_GT(x(), 9.9) << "refused at the braking point, not earlier";
  rig.run_ms(20);
  EXPECT_LE(x(), 10.0 + 1e-9) << "the axis stops inside its range";
  EXPECT_EQ(v_out(), 0.0);
  EXPECT_EQ(rig.seen.front().source, std::string("safety.X"));
}

TEST_F(SupervisorRig, SpeedAboveVmaxIsClampedWithAWarning) {
  command(50.0);
  rig.step();
  rig.step();
  EXPECT_EQ(v_out(), 20.0);
  EXPECT_EQ(rig.state(), MachineState::kReady) << "a clamp is a warning, not a fault";
  EXPECT_EQ(rig.alarms(AlarmCode::kSoftLimit), 1u);
  EXPECT_EQ(rig.seen.back().severity, rt::AlarmSeverity::kWarning);
  EXPECT_EQ(rig.seen.back().source, std::string("safety.X.v_max"));
  rig.run_ms(50);
  EXPECT_EQ(rig.alarms(AlarmCode::kSoftLimit), 1u) << "one alarm per occurrence";
  EXPECT_EQ(rig.active(AlarmCode::kSoftLimit, "safety.X.v_max").count, 52u) << "counted";
  command(5.0);
  rig.run_ms(2);
  EXPECT_EQ(rig.active(AlarmCode::kSoftLimit, "safety.X.v_max").count, 0u) << "cleared";
  command(50.0);
  rig.run_ms(2);
  EXPECT_EQ(rig.alarms(AlarmCode::kSoftLimit), 2u) << "a new occurrence is raised again";
}

// A jammed axis: the drive stops moving it while the command goes on.
TEST_F(SupervisorRig, JammedAxisGivesAFollowingErrorOncePerOccurrence) {
  command(10.0);
  rig.run_ms(50);
  ASSERT_EQ(rig.alarms(AlarmCode::kFollowingError), 0u);
  ASSERT_TRUE(rig.vars().write("p.drive.k", 0.0));  // jam (applied at the next cycle)
  // Limit at 10 mm/s: 0.05 + 0.45 · 10/20 = 0.275 mm, reached after 27.5 ms at 10 mm/s.
  const int n = rig.step_until([&] { return rig.state() == MachineState::kFault; }, 100);
  EXPECT_GE(n, 27);
  EXPECT_LE(n, 30) << "following error within 30 cycles of the jam";
  EXPECT_EQ(rig.machine().last_cause(), AlarmCode::kFollowingError);
  EXPECT_EQ(v_out(), 0.0) << "axis command 0 in the cycle the error was found";
  EXPECT_FALSE(generator());
  ASSERT_EQ(rig.alarms(AlarmCode::kFollowingError), 1u);
  EXPECT_EQ(rig.seen.back().source, std::string("safety.X"));
  EXPECT_EQ(rig.seen.back().time.count() % 1000000, 0) << "the raising cycle's release";

  // In the safe state the model follows the axis: the condition is gone, the latch opens.
  rig.run_ms(5);
  EXPECT_EQ(rig.active(AlarmCode::kFollowingError, "safety.X").count, 0u);
  // Reset with the jam still there: a new occurrence, raised again.
  ASSERT_EQ(rig.machine().command(rt::MachineCommand::kReset), rt::CommandResult::kOk);
  rig.step_until([&] { return rig.state() == MachineState::kFault; }, 100);
  EXPECT_EQ(rig.machine().last_cause(), AlarmCode::kFollowingError);
  EXPECT_EQ(rig.alarms(AlarmCode::kFollowingError), 2u);
}

TEST_F(SupervisorRig, DriverFaultStopsTheAxisInTheCycleItIsReported) {
  command(10.0);
  rig.run_ms(20);
  card().inject_fault(7);
  rig.step();
  EXPECT_EQ(rig.state(), MachineState::kFault);
  EXPECT_EQ(rig.alarms(AlarmCode::kIoFault), 1u);
  EXPECT_EQ(v_out(), 0.0);
  EXPECT_FALSE(generator());
  const double x0 = x();
  rig.run_ms(10);
  EXPECT_NEAR(x(), x0, 1e-9) << "the card echoes 0 in FAULT: the axis stands";
}

// An injected slow block (5 ms in a 1 ms cycle) trips the watchdog at the end of that cycle; the
// next cycle run holds the safe state.
TEST_F(SupervisorRig, SlowBlockTripsTheWatchdogAndTheNextCycleIsSafe) {
  command(10.0);
  rig.run_ms(20);
  ASSERT_TRUE(rig.vars().write("p.slow.cost_us", 5000.0));
  rig.step();  // the write is applied; this cycle costs 5 ms
  EXPECT_EQ(rig.state(), MachineState::kFault);
  EXPECT_EQ(rig.alarms(AlarmCode::kWatchdog), 1u);
  EXPECT_EQ(v_out(), 10.0) << "published before the watchdog saw the cycle's time";
  rig.run_ms(5);  // the slot of the next cycle after the overrun
  EXPECT_EQ(v_out(), 0.0);
  EXPECT_FALSE(generator());
}

// The supervisor's zeroing does not depend on the runtime releasing forces: a velocity forced
// on the pin itself, with no registry to release it, reads 0 in FAULT and ESTOP.
TEST(SupervisorUnit, SafeStateOverridesAForceOnThePin) {
  rt::Machine machine;
  machine.command(rt::MachineCommand::kPowerOn);
  rt::Input<double> vx;
  rt::Input<double> vz;
  rt::Output<double> x;
  rt::Output<double> z;
  rt::Input<bool> gen;
  rt::SupervisorSetup setup;
  setup.axes.push_back({machining::AxisLimits{'X', -100, 100, 30, 2000}, &vx, &x, 1.0, 0.1,
                        rt::RetractDirection::kNone});
  setup.axes.push_back({machining::AxisLimits{'Z', -60, 20, 30, 2000}, &vz, &z, 1.0, 0.1,
                        rt::RetractDirection::kPlus});
  setup.generator.push_back(&gen);
  rt::Supervisor sup(machine, setup, std::chrono::milliseconds(1));
  rt::CycleContext ctx;
  ctx.dt_s = 1e-3;
  ctx.period = std::chrono::milliseconds(1);

  vx.force(30.0);
  gen.force(true);
  vz.force(-5.0);
  sup.supervise(ctx);
  EXPECT_EQ(vx.get(), 30.0);
  EXPECT_TRUE(gen.get());

  rt::Alarm fault;
  fault.code = AlarmCode::kBlockFault;
  fault.source = "test";
  machine.raise(fault);
  sup.supervise(ctx);
  EXPECT_TRUE(vx.forced()) << "nothing released the force";
  EXPECT_EQ(vx.get(), 0.0);
  EXPECT_EQ(vz.get(), 0.0) << "no feed toward the work in FAULT";
  EXPECT_FALSE(gen.get());
  vz.force(5.0);
  sup.supervise(ctx);
  EXPECT_EQ(vz.get(), 5.0) << "Z may back off in FAULT";

  machine.command(rt::MachineCommand::kEstop);
  sup.supervise(ctx);
  EXPECT_EQ(vz.get(), 0.0) << "ESTOP: every axis stops";
  EXPECT_EQ(vx.requested(), 30.0);
}

}  // namespace
}  // namespace edm::test
