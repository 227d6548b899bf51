// Alarms are raised once per occurrence, then counted (DESIGN §11, issue 17 item 4): the latch
// of Machine, independent of who raises.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "edm/runtime/machine.hpp"

namespace edm::rt {
namespace {

using namespace std::chrono_literals;

std::vector<Alarm> drain(Machine& m) {
  std::vector<Alarm> out;
  Alarm a;
  while (m.pop_alarm(a)) {
    out.push_back(a);
  }
  return out;
}

Alarm make(AlarmCode code, const char* source, AlarmSeverity sev = AlarmSeverity::kFault) {
  Alarm a;
  a.code = code;
  a.severity = sev;
  a.source = source;
  a.text = "test";
  return a;
}

std::uint64_t count_of(const Machine& m, AlarmCode code) {
  std::array<ActiveAlarm, Machine::kLatchCapacity> active{};
  const std::size_t n = m.active_alarms(active.data(), active.size());
  for (std::size_t k = 0; k < n; ++k) {
    if (active[k].code == code) return active[k].count;
  }
  return 0;
}

TEST(AlarmLatch, RepeatsOfALatchedAlarmAreCountedNotQueued) {
  Machine m;
  m.command(MachineCommand::kPowerOn);
  constexpr int kRaises = 5000;
  int fresh = 0;
  for (int k = 0; k < kRaises; ++k) {
    m.note_release(TimePoint{1ms * (k + 1)});
    Alarm a = make(AlarmCode::kFollowingError, "cnc.job");
    a.time = TimePoint{1ms * (k + 1)};
    fresh += m.raise(a) ? 1 : 0;
  }
  EXPECT_EQ(fresh, 1);
  const std::vector<Alarm> q = drain(m);
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(q[0].time, 1ms) << "the first occurrence's time";
  EXPECT_EQ(count_of(m, AlarmCode::kFollowingError), static_cast<std::uint64_t>(kRaises));
  EXPECT_EQ(m.repeated_alarms(), static_cast<std::uint64_t>(kRaises - 1));
  EXPECT_EQ(m.dropped_alarms(), 0u) << "the queue never filled";
}

TEST(AlarmLatch, ClearOrResetEndsTheOccurrence) {
  Machine m;
  m.command(MachineCommand::kPowerOn);
  const Alarm warn = make(AlarmCode::kWatchdogWarning, "slow", AlarmSeverity::kWarning);
  EXPECT_TRUE(m.raise(warn));
  EXPECT_FALSE(m.raise(warn));
  m.clear_alarm(AlarmCode::kWatchdogWarning, "slow");
  EXPECT_EQ(count_of(m, AlarmCode::kWatchdogWarning), 0u);
  EXPECT_TRUE(m.raise(warn)) << "a new occurrence after the condition cleared";

  const Alarm fault = make(AlarmCode::kSoftLimit, "cnc.job");
  EXPECT_TRUE(m.raise(fault));
  EXPECT_FALSE(m.raise(fault));
  EXPECT_EQ(m.state(), MachineState::kFault);
  ASSERT_EQ(m.command(MachineCommand::kReset), CommandResult::kOk);
  EXPECT_TRUE(m.raise(fault)) << "a new occurrence after reset";
  EXPECT_EQ(m.state(), MachineState::kFault);
  EXPECT_EQ(drain(m).size(), 4u);
}

TEST(AlarmLatch, SourcesAreComparedByTextAndKeptApart) {
  Machine m;
  m.command(MachineCommand::kPowerOn);
  const std::string a1 = "prog.block";
  const std::string a2 = "prog.block";  // same text, another pointer
  const std::string b = "prog.other";
  EXPECT_TRUE(m.raise(make(AlarmCode::kBlockFault, a1.c_str())));
  EXPECT_FALSE(m.raise(make(AlarmCode::kBlockFault, a2.c_str())));
  EXPECT_TRUE(m.raise(make(AlarmCode::kBlockFault, b.c_str()))) << "another block: own alarm";
  EXPECT_TRUE(m.raise(make(AlarmCode::kIoFault, a1.c_str()))) << "another code: own alarm";
  EXPECT_EQ(drain(m).size(), 3u);
}

TEST(AlarmLatch, ARepeatStillForcesFault) {
  Machine m;
  m.command(MachineCommand::kPowerOn);
  const Alarm fault = make(AlarmCode::kFollowingError, "j");
  EXPECT_TRUE(m.raise(fault));
  // Reset races with the raiser: a repeat that lands after the reset is a new occurrence, and in
  // any case never leaves the machine out of FAULT.
  ASSERT_EQ(m.command(MachineCommand::kReset), CommandResult::kOk);
  m.raise(fault);
  EXPECT_EQ(m.state(), MachineState::kFault);
}

TEST(AlarmLatch, FullLatchTableStillQueuesEveryNewAlarm) {
  Machine m;
  m.command(MachineCommand::kPowerOn);
  std::vector<std::string> names;
  for (std::size_t k = 0; k < Machine::kLatchCapacity + 10; ++k) {
    names.push_back("src" + std::to_string(k));
  }
  for (const std::string& n : names) {
    m.raise(make(AlarmCode::kWatchdogWarning, n.c_str(), AlarmSeverity::kWarning));
  }
  EXPECT_EQ(drain(m).size(), names.size());
}

TEST(AlarmLatch, UnstampedAlarmsTakeTheLatestReleaseTime) {
  Machine m;
  m.command(MachineCommand::kPowerOn);
  m.note_release(TimePoint{7ms});
  m.raise(make(AlarmCode::kIoFault, "io"));
  m.command(MachineCommand::kEstop);  // as the bridge calls it: no time
  const std::vector<Alarm> q = drain(m);
  ASSERT_EQ(q.size(), 2u);
  EXPECT_EQ(q[0].time, 7ms);
  EXPECT_EQ(q[1].time, 7ms);
}

}  // namespace
}  // namespace edm::rt
