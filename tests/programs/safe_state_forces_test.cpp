// The safe state wins over forces (DESIGN §11, issue 17 item 4), on the whole drilling machine:
// a forced axis velocity or generator pin is released on entry to FAULT/ESTOP, cannot be forced
// again there, and reset does not bring it back. (A following error that persists — one alarm,
// counted, stamped with the raising cycle's release — is the safety supervisor's now:
// tests/safety/supervisor_rig_test.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "sim_machine.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

std::vector<rt::Alarm> drain(rt::Machine& m) {
  std::vector<rt::Alarm> out;
  rt::Alarm a;
  while (m.pop_alarm(a)) {
    out.push_back(a);
  }
  return out;
}

std::size_t count_code(const std::vector<rt::Alarm>& v, rt::AlarmCode c) {
  return static_cast<std::size_t>(
      std::count_if(v.begin(), v.end(), [c](const rt::Alarm& a) { return a.code == c; }));
}

class SafeStateForces : public ::testing::Test {
 protected:
  VirtualMachine m{"drill-sim"};
  rt::TimePoint t{};
  double x() { return m.vars().read("io.x_mm").value_or(NAN); }
  void run_for(rt::Duration d) {
    t += d;
    m.run_until(t);
  }
};

TEST_F(SafeStateForces, ForcedMotionAndGeneratorAreReleasedByFaultAndStayOffThroughReset) {
  run_for(50ms);
  ASSERT_EQ(m.runtime->machine().state(), rt::MachineState::kReady);
  ASSERT_TRUE(m.vars().force("io.vx_cmd", 30.0));
  ASSERT_TRUE(m.vars().force("io.gen_on", 1.0));
  const double x0 = x();
  run_for(10ms);
  ASSERT_GT(x() - x0, 0.02) << "the force moves X while READY (commissioning use)";

  // Any fault: the next cycle releases every force before the outputs are latched.
  rt::Alarm fault;
  fault.code = rt::AlarmCode::kBlockFault;
  fault.source = "test";
  fault.text = "injected fault";
  m.runtime->machine().raise(fault);
  run_for(1ms);
  EXPECT_EQ(m.runtime->machine().state(), rt::MachineState::kFault);
  EXPECT_TRUE(m.vars().forced().empty());
  EXPECT_EQ(m.vars().read("io.vx_cmd"), 0.0) << "the program's value, not the forced 30";
  EXPECT_EQ(m.vars().read("io.gen_on"), 0.0);
  // X decelerates (30 mm/s at 2000 mm/s² stops within 0.25 mm) and then stays put.
  run_for(50ms);
  const double x_stopped = x();
  run_for(500ms);
  EXPECT_NEAR(x(), x_stopped, 1e-3) << "X keeps moving in FAULT (forced: 15 mm in 0.5 s)";

  // No forcing in FAULT (nor ESTOP): refused with a reason, nothing forced.
  const rt::VarStatus again = m.vars().force("io.vx_cmd", 30.0);
  EXPECT_EQ(again.result, rt::VarResult::kInvalidState) << again.message;
  EXPECT_TRUE(m.vars().forced().empty());

  // Reset does not bring the force back: X holds where it stopped.
  ASSERT_EQ(m.runtime->machine().command(rt::MachineCommand::kReset), rt::CommandResult::kOk);
  run_for(500ms);
  EXPECT_NE(m.runtime->machine().state(), rt::MachineState::kRunning);
  EXPECT_TRUE(m.vars().forced().empty());
  EXPECT_NEAR(x(), x_stopped, 1e-3) << "X moved again after reset";

  const std::vector<rt::Alarm> alarms = drain(m.runtime->machine());
  EXPECT_EQ(count_code(alarms, rt::AlarmCode::kForcesReleased), 1u);
  for (const rt::Alarm& a : alarms) {
    if (a.code == rt::AlarmCode::kForcesReleased) {
      EXPECT_EQ(a.value, 2.0) << "two pins were forced";
    }
  }
}

TEST_F(SafeStateForces, EstopReleasesForcedProgramOutputsToo) {
  // Forcing the program's output that is wired to io.vz_cmd is the same fault by another road.
  run_for(50ms);
  ASSERT_TRUE(m.vars().force("cnc.job.axes.vz_cmd_mm_s", -20.0));
  run_for(5ms);
  ASSERT_EQ(m.vars().read("io.vz_cmd"), -20.0);
  m.runtime->machine().command(rt::MachineCommand::kEstop);
  run_for(1ms);
  EXPECT_EQ(m.runtime->machine().state(), rt::MachineState::kEstop);
  EXPECT_TRUE(m.vars().forced().empty());
  EXPECT_NE(m.vars().read("io.vz_cmd"), -20.0);
}

TEST_F(SafeStateForces, OperatorEstopAlarmCarriesTheLatestCycleTime) {
  // The bridge calls command() without a time: the alarm must not say t=0.
  run_for(123ms);
  ASSERT_EQ(m.runtime->machine().command(rt::MachineCommand::kEstop), rt::CommandResult::kOk);
  const std::vector<rt::Alarm> alarms = drain(m.runtime->machine());
  ASSERT_EQ(count_code(alarms, rt::AlarmCode::kEstop), 1u);
  for (const rt::Alarm& a : alarms) {
    if (a.code == rt::AlarmCode::kEstop) {
      EXPECT_EQ(a.time, 122ms) << "the release of the last cycle run";
    }
  }
}

}  // namespace
}  // namespace edm::test
