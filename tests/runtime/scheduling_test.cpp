// Task release order, counts and times under the virtual clock; overrun policies; watchdog.

#include "edm/runtime/scheduling.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/scheduler.hpp"
#include "support/files.hpp"
#include "support/runtime_fixture.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;
using rt::Duration;
using rt::TimePoint;

TEST(NextRelease, OnTimeCycleKeepsTheGrid) {
  auto n = rt::next_release(TimePoint{5ms}, TimePoint{5ms + 300us}, 1ms, rt::OverrunPolicy::kSkip);
  EXPECT_EQ(n.release, TimePoint{6ms});
  EXPECT_FALSE(n.overrun);
  EXPECT_EQ(n.omitted, 0u);
  // Ending exactly on the next slot is not an overrun.
  n = rt::next_release(TimePoint{5ms}, TimePoint{6ms}, 1ms, rt::OverrunPolicy::kSkip);
  EXPECT_FALSE(n.overrun);
}

// A cycle released at 0 on a 1 ms grid that ends at `end` overran; `policy` releases the next one
// at `release`, omitting `omitted` slots.
void expect_overrun(rt::OverrunPolicy policy, Duration end, Duration release,
                    std::uint64_t omitted) {
  const auto n = rt::next_release(TimePoint{0ms}, TimePoint{end}, 1ms, policy);
  EXPECT_TRUE(n.overrun);
  EXPECT_EQ(n.release, TimePoint{release});
  EXPECT_EQ(n.omitted, omitted);
}

TEST(NextRelease, SkipWaitsForTheNextSlotAndCountsThePassedOnes) {
  expect_overrun(rt::OverrunPolicy::kSkip, 3500us, 4ms, 3u);
  expect_overrun(rt::OverrunPolicy::kSkip, 1001us, 2ms, 1u);
}

TEST(NextRelease, AsapRunsTheLatestPassedSlotAtOnce) {
  expect_overrun(rt::OverrunPolicy::kAsap, 3500us, 3ms, 2u);
  expect_overrun(rt::OverrunPolicy::kAsap, 1500us, 1ms, 0u);
}

TEST(NextRelease, PropertyOverRandomCases) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 20000; ++i) {
    const Duration interval{1 + static_cast<std::int64_t>(rng() % 10'000'000)};
    const TimePoint release{static_cast<std::int64_t>(rng() % 1'000'000'000)};
    const TimePoint end = release + Duration{static_cast<std::int64_t>(rng() % 50'000'000)};
    for (auto policy : {rt::OverrunPolicy::kSkip, rt::OverrunPolicy::kAsap}) {
      const auto n = rt::next_release(release, end, interval, policy);
      ASSERT_EQ((n.release - release).count() % interval.count(), 0) << "on the grid";
      ASSERT_GT(n.release, release);
      if (!n.overrun) {
        ASSERT_EQ(n.release, release + interval);
        continue;
      }
      const auto slots = static_cast<std::uint64_t>((n.release - release) / interval);
      if (policy == rt::OverrunPolicy::kSkip) {
        ASSERT_GE(n.release, end) << "never released in the past";
        ASSERT_LT(n.release - interval, end) << "the first slot after the cycle";
      } else {
        ASSERT_LT(n.release, end) << "the latest passed slot, run late";
        ASSERT_GE(n.release + interval, end);
      }
      ASSERT_EQ(n.omitted, slots - 1);
    }
  }
}

TEST(FifoPriority, MapsZeroToNinetyAndNeverBelowOne) {
  EXPECT_EQ(rt::fifo_priority(0), 90);
  EXPECT_EQ(rt::fifo_priority(5), 85);
  EXPECT_EQ(rt::fifo_priority(31), 59);
  EXPECT_EQ(rt::fifo_priority(200), 1);
}

// Runs a built runtime's tasks on a virtual clock, in steps the test controls.
class VirtualRig {
 public:
  explicit VirtualRig(std::unique_ptr<rt::Runtime> r) : rt_(std::move(r)) {
    for (const auto& t : rt_->tasks()) {
      tasks_.push_back(t.get());
    }
    rt_->machine().command(rt::MachineCommand::kPowerOn);
    sched_ = std::make_unique<rt::VirtualScheduler>(tasks_, clock_);
  }
  void run_until(Duration t) { sched_->run_until(TimePoint{t}); }
  rt::Runtime& rt() { return *rt_; }
  rt::TaskStatsSnapshot stats(std::size_t i) { return tasks_[i]->stats().snapshot(); }

 private:
  std::unique_ptr<rt::Runtime> rt_;
  std::vector<rt::Task*> tasks_;
  rt::VirtualClock clock_;
  std::unique_ptr<rt::VirtualScheduler> sched_;
};

class VirtualRun : public ::testing::Test {
 protected:
  void SetUp() override {
    run_log().clear();
    run_log().reserve(100000);
  }
};

// A 1 ms priority-0 and a 10 ms priority-5 task, each running a Recorder.
const char* const kTwoTasks = "runtime/two_tasks.yaml";

TEST_F(VirtualRun, OneMsPrio0AndTenMsPrio5TasksReleaseInTimeThenPriorityOrder) {
  auto r = build_from_text(test_data(kTwoTasks));
  rt::RunOptions o;
  o.clock = rt::ClockKind::kVirtual;
  o.run_for = 100ms;
  r->run(o);
  const auto& log = run_log();
  std::size_t fast = 0;
  std::size_t slow = 0;
  TimePoint last{-1};
  for (std::size_t i = 0; i < log.size(); ++i) {
    const RunRecord& e = log[i];
    const bool is_fast = std::string(e.who) == "fast";
    const std::uint64_t k = is_fast ? fast++ : slow++;
    EXPECT_EQ(e.release, TimePoint{(is_fast ? 1ms : 10ms) * static_cast<std::int64_t>(k)});
    EXPECT_EQ(e.cycle, k);
    EXPECT_EQ(e.started, e.release) << "zero execution time: no latency";
    EXPECT_GE(e.release, last) << "releases in time order";
    last = e.release;
    if (!is_fast) {
      ASSERT_GT(i, 0u);
      EXPECT_EQ(std::string(log[i - 1].who), "fast") << "priority 0 first at equal times";
      EXPECT_EQ(log[i - 1].release, e.release);
    }
  }
  EXPECT_EQ(fast, 100u);
  EXPECT_EQ(slow, 10u);
  auto stats = r->stats_reports();
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[0].name, "slow");
  EXPECT_EQ(stats[0].stats.cycles, 10u);
  EXPECT_EQ(stats[1].stats.cycles, 100u);
  EXPECT_EQ(stats[1].stats.latency.max_us, 0.0);
  EXPECT_EQ(stats[1].stats.overruns, 0u);
}

TEST_F(VirtualRun, SlowCycleDelaysTheFastTaskWithoutPreemption) {
  // Virtual time does not preempt: the 10 ms task's 2.5 ms cycle at t=0 runs after the fast
  // task's cycle 0, so the fast release at 1 ms starts at 2.5 ms (1.5 ms late) and, since the
  // slot at 2 ms passed meanwhile, the skip policy omits it and resumes the grid at 3 ms.
  auto r = build_from_text(test_data("runtime/slow_cycle.yaml"));
  VirtualRig rig(std::move(r));
  rig.run_until(5ms);
  const auto& log = run_log();
  ASSERT_GE(log.size(), 4u);
  EXPECT_EQ(log[1].release, TimePoint{1ms});
  EXPECT_EQ(log[1].started, TimePoint{2500us});
  EXPECT_EQ(log[2].release, TimePoint{3ms});
  EXPECT_EQ(log[2].started, TimePoint{3ms});
  EXPECT_EQ(log[3].release, TimePoint{4ms});
  const auto fast = rig.stats(1);
  EXPECT_EQ(fast.latency.max_us, 1500.0);
  EXPECT_EQ(fast.overruns, 1u);
  EXPECT_EQ(fast.omitted_cycles, 1u);
}

// One 1 ms task with `task_extra` lines, running a Recorder and a Cost block with `cost` params.
std::string one_task(const std::string& task_extra, const std::string& cost) {
  return test_data("runtime/one_task.yaml", {{"task_extra", task_extra}, {"cost", cost}});
}

TEST_F(VirtualRun, SkipVersusAsapOmittedCycles) {
  // Cycle 0 costs 3.5 ms, then every cycle is free; 10 ms of virtual time.
  struct Case {
    const char* policy;
    std::uint64_t omitted;
    std::uint64_t cycles;
    std::vector<Duration> releases;
  };
  const Case cases[] = {
      {"skip", 3, 7, {0ms, 4ms, 5ms, 6ms, 7ms, 8ms, 9ms}},
      {"asap", 2, 8, {0ms, 3ms, 4ms, 5ms, 6ms, 7ms, 8ms, 9ms}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.policy);
    run_log().clear();
    VirtualRig rig(build_from_text(
        one_task(std::string("    overrun: ") + c.policy, "cost_us: 3500, cycles: 1")));
    rig.run_until(10ms);
    const auto s = rig.stats(0);
    EXPECT_EQ(s.overruns, 1u);
    EXPECT_EQ(s.omitted_cycles, c.omitted);
    EXPECT_EQ(s.cycles, c.cycles);
    ASSERT_EQ(run_log().size(), c.releases.size());
    for (std::size_t i = 0; i < c.releases.size(); ++i) {
      EXPECT_EQ(run_log()[i].release, TimePoint{c.releases[i]});
    }
    // Every cycle happened on a grid slot or was counted as omitted: nothing vanishes.
    EXPECT_EQ(s.cycles + s.omitted_cycles, 10u);
  }
}

struct WatchdogCase {
  const char* name;
  const char* cost;  // Cost block params
  bool expect_fault;
  std::uint64_t fault_cycle;  // cycle whose end trips the watchdog
};

class WatchdogSemantics : public VirtualRun, public ::testing::WithParamInterface<WatchdogCase> {};

TEST_P(WatchdogSemantics, TripsOnTheNthConsecutiveOverrunOrOneOverTimeTimesSensitivity) {
  const WatchdogCase& c = GetParam();
  // time 1 ms, sensitivity 3; the task interval is 5 ms so injected costs never overrun it.
  std::string cfg = one_task("    watchdog: {time: 1ms, sensitivity: 3, action: fault}", c.cost);
  cfg.replace(cfg.find("interval: 1ms"), 13, "interval: 5ms");
  VirtualRig rig(build_from_text(cfg));
  auto& driver = dynamic_cast<rt::LoopbackDriver&>(rig.rt().driver());
  for (std::uint64_t k = 0; k < 10; ++k) {
    rig.run_until(5ms * static_cast<std::int64_t>(k + 1));
    const bool faulted = rig.rt().machine().state() == rt::MachineState::kFault;
    EXPECT_EQ(faulted, c.expect_fault && k >= c.fault_cycle) << "after cycle " << k;
  }
  EXPECT_EQ(driver.safe_state_entries(), c.expect_fault ? 1 : 0);
  if (c.expect_fault) {
    EXPECT_EQ(rig.rt().machine().last_cause(), rt::AlarmCode::kWatchdog);
    // The cycle after the trip already runs in FAULT.
    EXPECT_EQ(run_log()[c.fault_cycle + 1].state, rt::MachineState::kFault);
    EXPECT_EQ(run_log()[c.fault_cycle].state, rt::MachineState::kReady);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Codesys, WatchdogSemantics,
    ::testing::Values(
        WatchdogCase{"ThreeConsecutive", "cost_us: 1200, from_cycle: 2, cycles: 3", true, 4},
        WatchdogCase{"TwoConsecutiveOnly", "cost_us: 1200, from_cycle: 2, cycles: 2", false, 0},
        WatchdogCase{"ExactlyTimeIsNotOver", "cost_us: 1000", false, 0},
        WatchdogCase{"SingleOverTimeTimesSensitivity", "cost_us: 3001, from_cycle: 1, cycles: 1",
                     true, 1},
        WatchdogCase{"SingleJustUnderThreeTimes", "cost_us: 2999, from_cycle: 1, cycles: 1", false,
                     0}),
    [](const auto& tpi) { return std::string(tpi.param.name); });

TEST_F(VirtualRun, WatchdogWarnCountsButDoesNotFault) {
  std::string cfg = one_task("    watchdog: {time: 1ms, sensitivity: 1, action: warn}",
                             "cost_us: 1500, from_cycle: 0, cycles: 4");
  cfg.replace(cfg.find("interval: 1ms"), 13, "interval: 5ms");
  VirtualRig rig(build_from_text(cfg));
  rig.run_until(50ms);
  EXPECT_EQ(rig.rt().machine().state(), rt::MachineState::kReady);
  EXPECT_EQ(rig.rt().tasks()[0]->watchdog_warnings(), 4u);
  rt::Alarm a;
  int warnings = 0;
  while (rig.rt().machine().pop_alarm(a)) {
    EXPECT_EQ(a.code, rt::AlarmCode::kWatchdogWarning);
    EXPECT_EQ(a.severity, rt::AlarmSeverity::kWarning);
    ++warnings;
  }
  // Four overrunning cycles in a row are one occurrence: one alarm, three repeats counted.
  EXPECT_EQ(warnings, 1);
  EXPECT_EQ(rig.rt().machine().repeated_alarms(), 3u);
}

TEST_F(VirtualRun, SameConfigGivesTheSameRunTwice) {
  auto once = [] {
    run_log().clear();
    VirtualRig rig(build_from_text(test_data(kTwoTasks)));
    rig.run_until(50ms);
    std::vector<std::pair<std::string, TimePoint>> seq;
    for (const auto& e : run_log()) {
      seq.emplace_back(e.who, e.release);
    }
    return seq;
  };
  EXPECT_EQ(once(), once());
}

}  // namespace
}  // namespace edm::test
