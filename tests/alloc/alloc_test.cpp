// Zero heap allocations inside a cycle: global operator new/delete are replaced in this test
// executable (below; alloc_counter.hpp) and count the calls made on the thread that runs the
// cycles while it runs them. The cycles run on the test thread (a virtual clock, run_cycle
// called here); another thread's allocations (a driver's exchange thread) are not counted.

#include <gtest/gtest.h>

#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <new>
#include <sstream>
#include <thread>
#include <vector>

#include "alloc/alloc_counter.hpp"
#include "alloc/drill_job.hpp"
#include "edm/machining/motion_block.hpp"
#include "edm/programs/register.hpp"
#include "edm/sim/sim_driver.hpp"
#include "support/files.hpp"
#include "support/runtime_fixture.hpp"

// The replacements are in this file, the one that holds TheCounterSeesAllocations: with them in
// another translation unit GCC's -O2 removes the `new`/`delete` pair of an object that does not
// escape (allocation DCE) and the guard would see one allocation of its two.
namespace {

using edm::test::allocations_in;
using edm::test::g_all_allocations;
using edm::test::g_allocations;
using edm::test::t_counting;

void count() noexcept {
  g_all_allocations.fetch_add(1, std::memory_order_relaxed);
  if (t_counting) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
  }
}

void* counted_alloc(std::size_t n) {
  count();
  if (void* p = std::malloc(n == 0 ? 1 : n)) {
    return p;
  }
  throw std::bad_alloc();
}

void* counted_aligned_alloc(std::size_t n, std::align_val_t al) {
  count();
  const auto a = static_cast<std::size_t>(al);
  if (void* p = std::aligned_alloc(a, (n + a - 1) / a * a)) {
    return p;
  }
  throw std::bad_alloc();
}

}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_alloc(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t a) { return counted_aligned_alloc(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return counted_aligned_alloc(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace edm::test {
namespace {

using namespace std::chrono_literals;

// A realistic gap-control-like program: signal source, loopback feedback, filters, a PI-ish
// integrator, limits, cross-task wires, a trace, a watchdog.
constexpr const char* kRealistic = R"(version: 1
machine:
  name: alloc
  io: {driver: loopback, task: fast, params: {channels: 4}}
tasks:
  - name: fast
    interval: 1ms
    priority: 0
    watchdog: {time: 1ms, sensitivity: 2, action: warn}
    programs: [gap]
  - {name: slow, interval: 10ms, priority: 5, programs: [supervisor]}
programs:
  - name: gap
    blocks:
      - {name: ref, type: SineSource, params: {amplitude: 2.0, frequency_hz: 5}}
      - {name: meas, type: LowPass, params: {tau: 2ms}}
      - {name: avg, type: MovingAverage, params: {window: 64}}
      - {name: err, type: Gain, params: {k: -1.0}}
      - {name: integ, type: Integrator, params: {k: 20, min: -5, max: 5}}
      - {name: lim, type: Limiter, params: {min: -3, max: 3, rate: 500}}
      - {name: probe, type: ParamProbe}
    wires:
      meas.in: io.ai0
      avg.in: meas.out
      err.in: avg.out
      integ.in: ref.out
      lim.in: integ.out
      io.ao0: lim.out
      io.do0: lim.limited
  - name: supervisor
    blocks:
      - {name: slowavg, type: MovingAverage, params: {window: 16}}
      - {name: slowlp, type: LowPass, params: {tau: 100ms}}
    wires:
      slowavg.in: gap.lim.out
      slowlp.in: slowavg.out
trace:
  variables: [gap.ref.out, gap.lim.out, io.ai0, io.di0, supervisor.slowlp.out]
  capacity: 4096
)";

TEST(Allocations, NoneInsideCyclesOfARealisticProgram) {
  auto r = build_from_text(kRealistic);
  r->machine().command(rt::MachineCommand::kPowerOn);
  rt::VirtualClock clock;
  std::vector<rt::Task*> tasks;
  for (const auto& t : r->tasks()) {
    tasks.push_back(t.get());
  }
  std::ostringstream sink;
  std::size_t total = 0;
  for (int round = 0; round < 4; ++round) {
    // Non-RT work between rounds (allowed to allocate): parameter writes queued for the RT side,
    // a force, trace drained.
    ASSERT_TRUE(r->variables().write("gap.probe.gain", 3.0 + round));
    ASSERT_TRUE(r->variables().write("gap.meas.tau", 0.001 * (round + 1)));
    ASSERT_TRUE(r->variables().force("gap.err.out", 0.5 * round));
    total += allocations_in([&] {
      for (int k = 0; k < 500; ++k) {
        const rt::TimePoint release{1ms * (round * 500 + k)};
        clock.advance_to(release);
        tasks[0]->run_cycle(release, clock);
        if (k % 10 == 0) {
          tasks[1]->run_cycle(release, clock);
        }
      }
    });
    r->trace().drain(sink);
  }
  EXPECT_EQ(total, 0u);
  // The cycles did real work: parameters applied, trace recorded, values moving.
  EXPECT_EQ(r->variables().read("gap.probe.gain_seen"), 6.0);
  EXPECT_EQ(tasks[0]->cycles(), 2000u);
  EXPECT_EQ(r->trace().dropped(), 0u);
  EXPECT_GT(sink.str().size(), 2000u * 10);
}

// Builds a config with the built-in blocks, the C++ PROGRAM types and the simulator driver.
std::unique_ptr<rt::Runtime> build_sim_machine(const rt::Config& cfg) {
  static const auto registries = [] {
    std::pair<rt::BlockRegistry, rt::DriverRegistry> r;
    blocks::register_builtin_blocks(r.first);
    programs::register_builtin_programs(r.first);
    sim::register_sim_driver(r.second);
    return r;
  }();
  auto r = rt::Runtime::build(cfg, registries.first, registries.second);
  r->machine().command(rt::MachineCommand::kPowerOn);
  return r;
}

std::unique_ptr<rt::Runtime> build_shipped(const std::string& machine) {
  return build_sim_machine(
      rt::parse_config_file(std::string(EDM_SOURCE_DIR) + "/config/machines/" + machine + ".yaml"));
}

// Runs `cycles` 1 ms cycles of the first task on a virtual clock and returns the allocations
// made inside them; the trace is drained (non-RT work, not counted) every 500 cycles.
std::size_t allocations_in_cycles(rt::Runtime& r, int cycles) {
  rt::VirtualClock clock;
  auto& task = *r.tasks()[0];
  std::ostringstream sink;
  std::size_t total = 0;
  for (int k = 0; k < cycles; ++k) {
    const rt::TimePoint release{1ms * k};
    clock.advance_to(release);
    total += allocations_in([&] { task.run_cycle(release, clock); });
    if (k % 500 == 499) {
      r.trace().drain(sink);
    }
  }
  return total;
}

// Runs `cycles` 1 ms cycles of the shipped `machine` and expects no allocation inside them.
std::unique_ptr<rt::Runtime> run_shipped(const std::string& machine, int cycles) {
  auto r = build_shipped(machine);
  EXPECT_EQ(allocations_in_cycles(*r, cycles), 0u) << machine;
  return r;
}

class DrillMachines : public ::testing::TestWithParam<const char*> {};

TEST_P(DrillMachines, NoAllocationInsideCyclesWhileAJobDrills) {
  // The whole machine of config/machines/<param>.yaml running a job from its JobStore: the
  // EdmJob sequencer (rapid, condition, gap-controlled drilling with wear compensation; in
  // drill-fuzzy-sim seed 003's counter and fuzzy LUT servo drive it) and the simulator inside the
  // I/O task's input latch. 3 s of drilling, ~60 000 pulses.
  auto r = build_shipped(GetParam());
  // Loaded non-RT, before the counted cycles.
  ASSERT_EQ(r->job().load(edm::test::drill_job()), rt::LoadResult::kOk);
  ASSERT_EQ(r->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
  EXPECT_EQ(allocations_in_cycles(*r, 3000), 0u);
  EXPECT_GT(r->variables().read("io.depth_mm").value(), 0.1) << "it really drilled";
  EXPECT_EQ(r->variables().read("cnc.job.drill.state"), 2.0)
      << "drilling from the job; machine " << rt::to_string(r->machine().state()) << ", cause "
      << static_cast<int>(r->machine().last_cause());
}

INSTANTIATE_TEST_SUITE_P(Shipped, DrillMachines, ::testing::Values("drill-sim", "drill-fuzzy-sim"),
                         [](const ::testing::TestParamInfo<const char*>& p) {
                           return std::string(p.param) == "drill-sim" ? "PGapController"
                                                                      : "FuzzyServo";
                         });

TEST(Allocations, NoneInsideCyclesOfTheWireMachineCuttingAlongItsPath) {
  // wire-sim.yaml (issue 34): EdmJob's wire cut (the gap servo along the path, its history ring)
  // and the simulator's plate field eroded in 2-D. 4 s: the rapid, then the cut into the plate.
  auto r = build_shipped("wire-sim");
  ASSERT_EQ(r->job().load(edm::test::wire_job()), rt::LoadResult::kOk);
  ASSERT_EQ(r->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
  EXPECT_EQ(allocations_in_cycles(*r, 4000), 0u);
  EXPECT_GT(r->variables().read("cnc.job.wire.block_done_mm").value(), 0.05) << "it cut";
  EXPECT_GT(r->variables().read("io.depth_mm").value(), 0.0) << "material was removed";
}

// The operator's manual motion (issue 21) on drill-sim: a homing of Z (switch, back-off, latch,
// encoder set), a distance jog, a continuous jog refreshed then stopped, and a touch-off of the
// surface (touch mode, fast and slow approach) — every cycle of them counted. The requests are
// made between cycles (the bridge's thread in use), not counted.
TEST(Allocations, NoneInsideCyclesOfTheManualMotion) {
  auto r = build_shipped("drill-sim");
  auto run_until_idle = [&](std::uint64_t seq, int max_cycles) {
    rt::VirtualClock clock;
    static std::int64_t k = 0;
    auto& task = *r->tasks()[0];
    std::size_t total = 0;
    for (int n = 0; n < max_cycles; ++n, ++k) {
      const rt::TimePoint release{1ms * k};
      clock.advance_to(release);
      total += allocations_in([&] { task.run_cycle(release, clock); });
      const rt::ManualStatus st = r->manual().status();
      if (st.seen_seq >= seq && !st.busy) break;
    }
    return total;
  };
  rt::ManualRequest home;
  home.op = rt::ManualOp::kHome;
  home.axes = 0x4;
  EXPECT_EQ(run_until_idle(r->manual().request(home), 20'000), 0u);
  EXPECT_TRUE(r->manual().status().result.ok);
  rt::ManualRequest jog;
  jog.op = rt::ManualOp::kJogDistance;
  jog.axis = 2;
  jog.value = -10.0;
  EXPECT_EQ(run_until_idle(r->manual().request(jog), 20'000), 0u);
  jog.value = -4.9;
  EXPECT_EQ(run_until_idle(r->manual().request(jog), 20'000), 0u);
  rt::ManualRequest touch;
  touch.op = rt::ManualOp::kTouch;
  touch.target = rt::TouchTarget::kZ;
  EXPECT_EQ(run_until_idle(r->manual().request(touch), 60'000), 0u);
  EXPECT_TRUE(r->manual().status().result.ok) << rt::to_string(r->manual().status().result.error);
  rt::ManualRequest vel;
  vel.op = rt::ManualOp::kJogVelocity;
  vel.axis = 0;
  vel.value = 2.0;
  EXPECT_EQ(run_until_idle(r->manual().request(vel), 100), 0u);  // refreshed below, then stopped
  EXPECT_EQ(run_until_idle(r->manual().request(vel), 100), 0u);
  rt::ManualRequest stop;
  stop.op = rt::ManualOp::kStop;
  EXPECT_EQ(run_until_idle(r->manual().request(stop), 2'000), 0u);
  EXPECT_EQ(r->manual().status().result.error, rt::ManualError::kStopped);
}

// Every seed-004 block in one program on the simulated drill: Td detector → P gap controller →
// wear compensation → Z, interpolators and position loops for X/Y, orbit expander, polarity
// switch and short retract (tests/data/alloc/seed_004.yaml).
TEST(Allocations, NoneInsideCyclesOfTheSeed004Blocks) {
  auto r =
      build_sim_machine(rt::parse_config_text(test_data("alloc/seed_004.yaml"), "alloc-004.yaml"));
  EXPECT_EQ(allocations_in_cycles(*r, 2000), 0u);
  EXPECT_GT(r->variables().read("io.depth_mm").value(), 0.1) << "the Td controller drilled";
  EXPECT_GT(r->variables().read("drill.arc.swept_rad").value(), 1.0) << "the arc moved";
}

// Every seed-003 and seed-000 block on the simulated wire machine: discharge-state counter →
// fuzzy servo table → Z feed; Rab → Butterworth → GM(1,1) → self-tuning fuzzy PI → arc-off time
// and servo reference voltage. The fuzzy rules come from YAML text (parsed at load time only)
// (tests/data/alloc/seed_003_000.yaml).
TEST(Allocations, NoneInsideCyclesOfTheSeed003And000Blocks) {
  auto r = build_sim_machine(
      rt::parse_config_text(test_data("alloc/seed_003_000.yaml"), "alloc-003-000.yaml"));
  EXPECT_EQ(allocations_in_cycles(*r, 3000), 0u);
  const double pulses = r->variables().read("wire.dsc.open_count").value() +
                        r->variables().read("wire.dsc.normal_count").value() +
                        r->variables().read("wire.dsc.short_count").value();
  EXPECT_EQ(pulses, 32.0) << "the counter saw pulses";
  EXPECT_NE(r->variables().read("wire.pi.arc_off_time_us").value(), 20.0) << "the PI acted";
}

// Seed 001 and 002 blocks on the simulated sink machine: five-state ratios → SelfTuningRegulator
// → servo reference voltage (the machine's own servo) and pulse-off time; a stand-alone
// RecursiveLeastSquares; an IterativeLearningControl block learning over 100-sample cycles
// (tests/data/alloc/seed_001_002.yaml).
TEST(Allocations, NoneInsideCyclesOfTheSeed001And002Blocks) {
  auto r = build_sim_machine(
      rt::parse_config_text(test_data("alloc/seed_001_002.yaml"), "alloc-001-002.yaml"));
  EXPECT_EQ(allocations_in_cycles(*r, 3000), 0u);
  EXPECT_GT(r->variables().read("io.depth_mm").value(), 0.001) << "the machine servo sank";
  EXPECT_GE(r->variables().read("sink.ilc.cycles").value(), 29.0) << "the ILC learnt";
  EXPECT_EQ(r->variables().read("sink.ilcw.active").value(), 1.0) << "the warm start ended";
  EXPECT_EQ(r->variables().read("sink.sel.active1").value(), 1.0) << "the Select switched";
  EXPECT_NE(r->variables().read("sink.rls.trace_p").value(), 2000.0) << "the RLS estimated";
}

TEST(Allocations, NoneInsideCyclesOfTheDeepHoleDrillProgram) {
  // Approach, touch, drilling with wear compensation, on the simulated machine.
  auto r = run_shipped("drill-sim-program", 5000);
  EXPECT_EQ(r->variables().read("cycle.drill.state"), 2.0) << "drilling after 5 s";
}

TEST(Allocations, NoneInsideCyclesOfTheWireMachineWithItsControllerSwitch) {
  // Butterworth → GM(1,1) → SelfTuningFuzzyPI and the two Selects of the operator's switch.
  auto r = run_shipped("wire-stfpi-sim", 3000);
  EXPECT_EQ(r->variables().read("rupture.sel_u.active1"), 1.0);
}

TEST(Allocations, NoneInsideCyclesOfTheSinkMachineWithJumpsAndTheIlc) {
  // JumpCycle, the integral controller's warm cycles, the ILC's learning at each jump edge and
  // its take-over through the Select at the third jump (4.5 s).
  auto r = run_shipped("sink-ilc-sim", 5000);
  EXPECT_EQ(r->variables().read("gap.jump.jumps"), 3.0);
  EXPECT_EQ(r->variables().read("gap.ilc.active"), 1.0) << "the ILC drives after the take-over";
}

TEST(Allocations, NoneInsideCyclesOfTheSinkMachineWithJumpsAndTheStr) {
  // JumpCycle holding the STR through each jump and its approach (two jumps in 3.5 s).
  auto r = run_shipped("sink-str-jump-sim", 3500);
  EXPECT_EQ(r->variables().read("ratios.jump.jumps"), 2.0);
}

TEST(Allocations, NoneInsideCyclesOfTheWallFinishProgram) {
  run_shipped("finish-sim-program", 5000);  // polarity switch, then orbiting
}

TEST(Allocations, NoneInsideCyclesOfTheSafetySupervisorActing) {
  // sink-sim's supervisor refusing a forced feed at Z's soft limit (alarm 141, FAULT), then
  // holding the safe state; the alarms' text and sources are static, nothing is formatted. The
  // generator is disarmed: sparking, the short at the work would stop the feed first (below).
  auto r = build_shipped("sink-sim");
  ASSERT_NE(r->supervisor(), nullptr);
  r->machine().command(rt::MachineCommand::kPowerOn);
  ASSERT_TRUE(r->variables().force("io.gen_arm", 0.0));
  ASSERT_TRUE(r->variables().force("io.vz_cmd", -30.0));  // down to Z min = -60 in 2 s
  EXPECT_EQ(allocations_in_cycles(*r, 2500), 0u);
  EXPECT_EQ(r->machine().state(), rt::MachineState::kFault);
  EXPECT_EQ(r->machine().last_cause(), rt::AlarmCode::kSoftLimit);
  EXPECT_GT(r->supervisor()->refused_cycles(), 0u);
}

TEST(Allocations, NoneInsideCyclesOfTheShortStopActing) {
  // sink-sim's supervisor cutting a forced feed into the work in every cycle whose pulses read
  // short (machine.safety.short_stop, issue 31).
  auto r = build_shipped("sink-sim");
  r->machine().command(rt::MachineCommand::kPowerOn);
  ASSERT_TRUE(r->variables().force("io.vz_cmd", -5.0));
  EXPECT_EQ(allocations_in_cycles(*r, 2500), 0u);
  EXPECT_GT(r->supervisor()->short_stopped_cycles(), 0u);
}

TEST(Allocations, TheCounterSeesAllocations) {
  // Guards the guard: the replaced operator new really counts.
  g_allocations = 0;
  t_counting = true;
  auto* p = new std::vector<int>(100);
  t_counting = false;
  delete p;
  EXPECT_GE(g_allocations.load(), 2u);
}

TEST(Allocations, TheCounterSeesOnlyTheCycleThread) {
  // A driver's own thread (the Modbus exchange) allocates while the cycles run: not counted;
  // the thread that set t_counting is. The other thread is made before counting starts and
  // steps under a mutex and condition variable (futexes: neither allocates).
  std::mutex m;
  std::condition_variable cv;
  int step = 0;
  std::size_t seen_there = 0;  // allocations through operator new on the other thread
  std::thread other([&] {
    std::unique_lock lock(m);
    cv.wait(lock, [&] { return step == 1; });
    const std::size_t before = g_all_allocations.load();
    auto* p = new std::vector<int>(100);
    seen_there = g_all_allocations.load() - before;
    delete p;
    step = 2;
    cv.notify_all();
  });
  g_allocations = 0;
  t_counting = true;
  {
    std::unique_lock lock(m);
    step = 1;
    cv.notify_all();
    cv.wait(lock, [&] { return step == 2; });
  }
  const std::size_t counted_while_other_allocated = g_allocations.load();
  auto* mine = new std::vector<int>(100);
  t_counting = false;
  delete mine;
  other.join();
  EXPECT_GE(seen_there, 2u) << "the other thread's allocations went through operator new";
  EXPECT_EQ(counted_while_other_allocated, 0u) << "another thread's allocations are not counted";
  EXPECT_GE(g_allocations.load(), 2u) << "the counting thread's are";
}

}  // namespace
}  // namespace edm::test
