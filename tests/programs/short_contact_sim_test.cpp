// Short circuits on the simulated drilling machine (issue 19): the simulator's contact injection
// (a chip or debris bridge meeting the tip at a depth) against DeepHoleDrill's gap truth, retract
// along the path and alarm 150. Every cycle of every run asserts that the Z command never points
// toward the work while the gap reads short.
//
// ShortFigures.TwentySeeds prints the figures of docs/benchmarks.md ("Short circuits"), seeds
// 1-20; nothing was tuned on them (the retract parameters are ShortRetract's and DeepHoleDrill's
// defaults).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "edm/programs/deep_hole_drill.hpp"
#include "sim_machine.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

const std::string kConfig = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim-program.yaml";

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct ContactOutcome {
  bool done{false};
  bool alarm150{false};
  double depth_mm{0.0};          // io.depth_mm at the end
  std::int64_t retracts{0};      // cycle.drill.short_retracts
  double lost_s{0.0};            // cycle.drill.short_time_s
  std::int64_t latency{-1};      // cycles from the detection to the retract (first contact)
  std::int64_t short_cycles{0};  // cycles reading short (short_now: the window or the cycle)
  std::int64_t violations{0};    // cycles fed toward the work while the gap read short
  double z_alarm{0.0}, z_end{0.0};
  bool gen_on_end{true};
  double vz_end{1.0};
};

// `sim_extra` is appended to the sim's params (e.g. ", contact_at_depth_mm: 8").
ContactOutcome run(int seed, const std::string& sim_extra, double limit_s = 200.0) {
  std::string text = slurp(kConfig);
  const std::string from = "params: {preset: drill, seed: 1}";
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos);
  text.replace(at, from.size(),
               "params: {preset: drill, seed: " + std::to_string(seed) + sim_extra + "}");
  auto r = build_sim_machine(rt::parse_config_text(text, "drill-sim-program.yaml"));
  r->machine().command(rt::MachineCommand::kPowerOn);
  rt::VirtualClock clock;
  auto& task = *r->tasks()[0];
  task.detach_trace();
  auto& vars = r->variables();
  const auto pin = [&](const char* n) { return vars.find(n)->pin; };
  const rt::PinRef state = pin("cycle.drill.state"), reads_short = pin("cycle.drill.short_now"),
                   active = pin("cycle.drill.retract.active"), vz = pin("cycle.drill.vz_cmd_mm_s"),
                   io_vz = pin("io.vz_cmd"), z = pin("io.z_mm");
  ContactOutcome o;
  std::int64_t detected = -1;  // short_now for retract.short_cycles consecutive cycles
  std::int64_t run_length = 0;
  const auto needed =
      static_cast<std::int64_t>(vars.read("cycle.drill.retract.short_cycles").value());
  const auto cycles = static_cast<std::int64_t>(limit_s * 1000.0);
  for (std::int64_t k = 0; k < cycles; ++k) {
    const rt::TimePoint release{1ms * k};
    clock.advance_to(release);
    const double z_before = rt::read_pin_as_double(z);
    task.run_cycle(release, clock);
    if (rt::read_pin_as_double(reads_short) != 0.0) {
      ++o.short_cycles;
      if (++run_length == needed && detected < 0) detected = k;
      if (rt::read_pin_as_double(vz) < 0.0 || rt::read_pin_as_double(io_vz) < 0.0) {
        ++o.violations;
      }
    } else {
      run_length = 0;
    }
    if (o.latency < 0 && detected >= 0 && rt::read_pin_as_double(active) != 0.0) {
      o.latency = k - detected;
    }
    if (!o.alarm150 && r->machine().last_cause() == rt::AlarmCode::kShortCircuit) {
      o.alarm150 = true;
      o.z_alarm = z_before;
    }
    const double s = rt::read_pin_as_double(state);
    if (s == 4.0) {
      o.done = true;
      break;
    }
    if (o.alarm150 && s == 0.0) break;  // backed off and holding
  }
  o.depth_mm = vars.read("io.depth_mm").value();
  o.retracts = static_cast<std::int64_t>(vars.read("cycle.drill.short_retracts").value());
  o.lost_s = vars.read("cycle.drill.short_time_s").value();
  o.z_end = rt::read_pin_as_double(z);
  o.gen_on_end = vars.read("io.gen_on").value() != 0.0;
  o.vz_end = rt::read_pin_as_double(io_vz);
  return o;
}

const std::string kTransient = ", contact_at_depth_mm: 8, contact_clear_um: 20";
const std::string kPersistent =
    ", contact_at_depth_mm: 8, contact_clear_um: 20, "
    "contact_persistent: true";

class ContactSeeds : public ::testing::TestWithParam<int> {};

TEST_P(ContactSeeds, ATransientContactRetractsResumesAndTheHoleReachesItsDepth) {
  const ContactOutcome plain = run(GetParam(), "");
  const ContactOutcome hit = run(GetParam(), kTransient);
  ASSERT_TRUE(plain.done);
  ASSERT_TRUE(hit.done) << "depth " << hit.depth_mm;
  EXPECT_EQ(hit.violations, 0) << "fed toward the work while the gap read short";
  EXPECT_EQ(plain.violations, 0);
  ASSERT_GE(hit.latency, 0) << "the contact was met and retracted from";
  EXPECT_LE(hit.latency, 2) << "retract within 2 cycles of the detection";
  EXPECT_GE(hit.retracts, 1);
  EXPECT_FALSE(hit.alarm150);
  EXPECT_NEAR(hit.depth_mm, 20.0, 0.02) << "the same tolerance as without the contact";
  EXPECT_NEAR(plain.depth_mm, 20.0, 0.02);
}

TEST_P(ContactSeeds, APersistentContactGivesNRetractsThenAlarm150GeneratorOffZBackedOff) {
  const ContactOutcome o = run(GetParam(), kPersistent);
  EXPECT_EQ(o.violations, 0);
  ASSERT_TRUE(o.alarm150) << "retracts " << o.retracts;
  EXPECT_EQ(o.retracts, programs::DeepHoleDrillParams{}.shorts.short_retracts_max) << "exactly N";
  EXPECT_FALSE(o.done);
  EXPECT_FALSE(o.gen_on_end);
  EXPECT_EQ(o.vz_end, 0.0);
  EXPECT_GE(o.z_end - o.z_alarm, 0.9 * programs::DeepHoleDrillParams{}.short_backoff_mm);
}

INSTANTIATE_TEST_SUITE_P(Seeds, ContactSeeds, ::testing::Values(1, 2, 3));

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}
double sd(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return v.size() > 1 ? std::sqrt(s / static_cast<double>(v.size() - 1)) : 0.0;
}

// The figures over seeds 1-20 (docs/benchmarks.md). Also a test: every seed must pass. Under a
// sanitizer (about 9x slower: 210 s for twenty seeds, near ctest's 300 s timeout on a loaded
// machine) seeds 1-5: the sanitizers look for memory errors, not figures.
#if defined(EDM_UNDER_SANITIZER)
constexpr int kLastSeed = 5;
#else
constexpr int kLastSeed = 20;
#endif

TEST(ShortFigures, TwentySeeds) {
  std::vector<double> lost, latency, err_plain, err_hit, tries;
  int violations = 0, alarms_exact = 0;
  for (int seed = 1; seed <= kLastSeed; ++seed) {
    const ContactOutcome plain = run(seed, "");
    const ContactOutcome hit = run(seed, kTransient);
    const ContactOutcome stuck = run(seed, kPersistent);
    ASSERT_TRUE(plain.done && hit.done) << "seed " << seed;
    violations += static_cast<int>(plain.violations + hit.violations + stuck.violations);
    latency.push_back(static_cast<double>(hit.latency));
    if (hit.retracts > 0) lost.push_back(hit.lost_s / static_cast<double>(hit.retracts));
    err_plain.push_back((plain.depth_mm - 20.0) * 1000.0);
    err_hit.push_back((hit.depth_mm - 20.0) * 1000.0);
    tries.push_back(static_cast<double>(stuck.retracts));
    if (stuck.alarm150 &&
        stuck.retracts == programs::DeepHoleDrillParams{}.shorts.short_retracts_max) {
      ++alarms_exact;
    }
    EXPECT_LE(hit.latency, 2) << "seed " << seed;
  }
  double max_latency = 0.0;
  for (double l : latency) max_latency = std::max(max_latency, l);
  std::printf(
      "[shorts] seeds 1-%d, 20 mm holes, contact at 8 mm (clear 20 um):\n"
      "[shorts]   retract latency after the detection: max %.0f cycles\n"
      "[shorts]   time lost per retract: %.3f +- %.3f s (mean +- SD)\n"
      "[shorts]   depth error without contact %+.1f +- %.1f um, with %+.1f +- %.1f um\n"
      "[shorts]   persistent contact: alarm 150 after exactly N = %lld retracts on %d/%d seeds\n"
      "[shorts]   cycles fed toward the work while reading short: %d\n",
      kLastSeed, max_latency, mean(lost), sd(lost), mean(err_plain), sd(err_plain), mean(err_hit),
      sd(err_hit),
      static_cast<long long>(programs::DeepHoleDrillParams{}.shorts.short_retracts_max),
      alarms_exact, kLastSeed, violations);
  EXPECT_EQ(violations, 0);
  EXPECT_EQ(alarms_exact, kLastSeed);
}

}  // namespace
}  // namespace edm::test
