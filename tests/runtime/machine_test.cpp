// The machine state machine: every (state, command) pair against the documented table, and
// fault/e-stop priorities.

#include "edm/runtime/machine.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <thread>

namespace edm::test {
namespace {

using rt::MachineCommand;
using rt::MachineState;

// Puts a fresh machine into state s through legal commands.
void drive_to(rt::Machine& m, MachineState s) {
  auto cmd = [&](MachineCommand c) { ASSERT_EQ(m.command(c), rt::CommandResult::kOk); };
  switch (s) {
    case MachineState::kOff: return;
    case MachineState::kReady: return cmd(MachineCommand::kPowerOn);
    case MachineState::kRunning: cmd(MachineCommand::kPowerOn); return cmd(MachineCommand::kStart);
    case MachineState::kHold:
      cmd(MachineCommand::kPowerOn);
      cmd(MachineCommand::kStart);
      return cmd(MachineCommand::kHold);
    case MachineState::kFault: {
      cmd(MachineCommand::kPowerOn);
      rt::Alarm a;
      a.code = rt::AlarmCode::kBlockFault;
      m.raise(a);
      return;
    }
    case MachineState::kEstop: cmd(MachineCommand::kPowerOn); return cmd(MachineCommand::kEstop);
  }
}

TEST(Machine, EveryStateCommandPairFollowsTheDocumentedTable) {
  using S = MachineState;
  using C = MachineCommand;
  // The table of docs/runtime.md: allowed transitions; everything else is kInvalidState and
  // leaves the state unchanged (estop in ESTOP is accepted and changes nothing).
  const std::map<std::pair<S, C>, S> allowed = {
      {{S::kOff, C::kPowerOn}, S::kReady},   {{S::kReady, C::kStart}, S::kRunning},
      {{S::kRunning, C::kHold}, S::kHold},   {{S::kHold, C::kResume}, S::kRunning},
      {{S::kRunning, C::kStop}, S::kReady},  {{S::kHold, C::kStop}, S::kReady},
      {{S::kFault, C::kReset}, S::kReady},   {{S::kEstop, C::kReset}, S::kReady},
      {{S::kReady, C::kPowerOff}, S::kOff},  {{S::kOff, C::kPowerOff}, S::kOff},
      {{S::kFault, C::kPowerOff}, S::kOff},  {{S::kEstop, C::kPowerOff}, S::kOff},
      {{S::kOff, C::kEstop}, S::kEstop},     {{S::kReady, C::kEstop}, S::kEstop},
      {{S::kRunning, C::kEstop}, S::kEstop}, {{S::kHold, C::kEstop}, S::kEstop},
      {{S::kFault, C::kEstop}, S::kEstop},   {{S::kEstop, C::kEstop}, S::kEstop},
  };
  const S states[] = {S::kOff, S::kReady, S::kRunning, S::kHold, S::kFault, S::kEstop};
  const C commands[] = {C::kPowerOn, C::kStart, C::kHold,  C::kResume,
                        C::kStop,    C::kReset, C::kEstop, C::kPowerOff};
  for (S s : states) {
    for (C c : commands) {
      rt::Machine m;
      drive_to(m, s);
      ASSERT_EQ(m.state(), s);
      const auto it = allowed.find({s, c});
      const rt::CommandResult r = m.command(c);
      SCOPED_TRACE(std::string(to_string(s)) + " + " + std::string(to_string(c)));
      if (it == allowed.end()) {
        EXPECT_EQ(r, rt::CommandResult::kInvalidState);
        EXPECT_EQ(m.state(), s);
      } else {
        EXPECT_EQ(r, rt::CommandResult::kOk);
        EXPECT_EQ(m.state(), it->second);
      }
    }
  }
}

// The feed override (issue 21): 0 … 1.5, anything else (negative, above, NaN) refused unchanged.
TEST(Machine, FeedOverrideAcceptsZeroToOneAndAHalfOnly) {
  rt::Machine m;
  EXPECT_EQ(m.feed_override(), 1.0) << "as programmed by default";
  EXPECT_TRUE(m.set_feed_override(0.0));
  EXPECT_EQ(m.feed_override(), 0.0);
  EXPECT_TRUE(m.set_feed_override(rt::Machine::kMaxFeedOverride));
  for (const double bad : {-0.01, 1.5000001, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    EXPECT_FALSE(m.set_feed_override(bad)) << bad;
    EXPECT_EQ(m.feed_override(), 1.5) << bad;
  }
}

TEST(Machine, FaultsBumpTheSafeEpochOnceAndKeepTheFirstCause) {
  rt::Machine m;
  drive_to(m, MachineState::kRunning);
  const auto e0 = m.safe_epoch();
  rt::Alarm a;
  a.code = rt::AlarmCode::kWatchdog;
  m.raise(a);
  a.code = rt::AlarmCode::kIoFault;
  m.raise(a);
  EXPECT_EQ(m.state(), MachineState::kFault);
  EXPECT_EQ(m.safe_epoch(), e0 + 1);
  EXPECT_EQ(m.last_cause(), rt::AlarmCode::kWatchdog);
  // E-stop outranks a fault: a new safe-state entry with its own cause.
  m.command(MachineCommand::kEstop);
  EXPECT_EQ(m.state(), MachineState::kEstop);
  EXPECT_EQ(m.safe_epoch(), e0 + 2);
  EXPECT_EQ(m.last_cause(), rt::AlarmCode::kEstop);
  // A fault during ESTOP does not leave ESTOP.
  m.raise(a);
  EXPECT_EQ(m.state(), MachineState::kEstop);
  // Warnings never change state.
  m.command(MachineCommand::kReset);
  a.severity = rt::AlarmSeverity::kWarning;
  m.raise(a);
  EXPECT_EQ(m.state(), MachineState::kReady);
}

TEST(Machine, AlarmQueueIsBoundedAndCountsDrops) {
  rt::Machine m;
  drive_to(m, MachineState::kReady);
  rt::Alarm a;
  a.severity = rt::AlarmSeverity::kWarning;
  for (std::size_t i = 0; i < rt::Machine::kAlarmCapacity + 10; ++i) {
    a.value = static_cast<double>(i);
    m.raise(a);
    m.clear_alarm(a.code, a.source);  // each raise a new occurrence (repeats are only counted)
  }
  EXPECT_EQ(m.dropped_alarms(), 10u);
  std::size_t n = 0;
  while (m.pop_alarm(a)) {
    EXPECT_EQ(a.value, static_cast<double>(n));
    ++n;
  }
  EXPECT_EQ(n, rt::Machine::kAlarmCapacity);
}

TEST(Machine, ConcurrentCommandsAndFaultsEndInAConsistentState) {
  // Hold/resume from one thread while another raises faults and resets: every transition is a
  // CAS, so each safe-state entry is counted exactly once.
  rt::Machine m;
  drive_to(m, MachineState::kRunning);
  std::atomic<bool> go{false};
  std::atomic<int> faults_entered{0};
  std::thread t1([&] {
    while (!go) {
    }
    for (int i = 0; i < 20000; ++i) {
      m.command(MachineCommand::kHold);
      m.command(MachineCommand::kResume);
      m.command(MachineCommand::kStart);
    }
  });
  std::thread t2([&] {
    while (!go) {
    }
    rt::Alarm a;
    a.severity = rt::AlarmSeverity::kFault;
    for (int i = 0; i < 20000; ++i) {
      const auto before = m.safe_epoch();
      m.raise(a);
      if (m.safe_epoch() != before) {
        faults_entered.fetch_add(1);
      }
      m.command(MachineCommand::kReset);
      rt::Alarm drop;
      while (m.pop_alarm(drop)) {
      }
    }
  });
  go = true;
  t1.join();
  t2.join();
  EXPECT_EQ(m.safe_epoch(), static_cast<std::uint64_t>(faults_entered.load()));
  const MachineState s = m.state();
  EXPECT_TRUE(s == MachineState::kReady || s == MachineState::kRunning || s == MachineState::kHold);
}

}  // namespace
}  // namespace edm::test
