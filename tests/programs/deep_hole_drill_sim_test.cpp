// DeepHoleDrill on the simulated drilling machine (config/machines/drill-sim-program.yaml):
// a 20 mm blind hole for seeds 1, 2, 3, with and without real-time wear compensation.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "edm/blocks/register.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/sim/sim_driver.hpp"
#include "sim_machine.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

const std::string kConfig = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim-program.yaml";

struct Outcome {
  bool done{false};
  double true_depth_mm{0.0};  // io.depth_mm at DONE
  double estimate_mm{0.0};    // drill.depth_reached_mm at DONE
  double wear_est_mm{0.0};    // drill.wear.wear_mm
  double electrode_used_mm{0.0};
  double drill_time_s{0.0};    // time in DRILL
  double short_fraction{0.0};  // Σ n_short / Σ all pulses while drilling
  double pulses{0.0};          // Σ all pulses while drilling
  double cycle_time_s{0.0};    // start to DONE
};

Outcome run(int seed, bool wear_comp, double limit_s = 200.0) {
  Outcome o;
  std::string text = read_file(kConfig);
  replace_once(text, "seed: 1", "seed: " + std::to_string(seed));
  if (!wear_comp) {
    replace_once(text, "drill.enable_wear_comp: true", "drill.enable_wear_comp: false");
  }
  SteppedMachine m(text, "drill-sim-program.yaml");
  auto& vars = m.vars;
  auto pin = [&](const char* name) {
    const rt::Variable* v = vars.find(name);
    EXPECT_NE(v, nullptr) << name;
    return v->pin;
  };
  const rt::PinRef state = pin("cycle.drill.state");
  const rt::PinRef n_short = pin("io.n_short");
  const rt::PinRef all[] = {pin("io.n_open"), pin("io.n_normal"), pin("io.n_transient_arc"),
                            pin("io.n_stable_arc"), n_short};
  double shorts = 0.0;
  double pulses = 0.0;
  std::int64_t drill_cycles = 0;
  const auto cycles = static_cast<std::int64_t>(limit_s * 1000.0);
  std::int64_t k = 0;
  double electrode0 = -1.0;
  for (; k < cycles; ++k) {
    m.run_cycle(k);
    if (electrode0 < 0.0) electrode0 = vars.read("io.electrode_mm").value();
    const double s = rt::read_pin_as_double(state);
    if (s == 2.0) {
      ++drill_cycles;
      shorts += rt::read_pin_as_double(n_short);
      for (const rt::PinRef& p : all) pulses += rt::read_pin_as_double(p);
    }
    if (s == 4.0) {
      o.done = true;
      break;
    }
  }
  o.true_depth_mm = vars.read("io.depth_mm").value();
  o.estimate_mm = vars.read("cycle.drill.depth_reached_mm").value();
  o.wear_est_mm = vars.read("cycle.drill.wear.wear_mm").value();
  o.electrode_used_mm = electrode0 - vars.read("io.electrode_mm").value();
  o.drill_time_s = static_cast<double>(drill_cycles) * 1e-3;
  o.pulses = pulses;
  o.short_fraction = pulses > 0.0 ? shorts / pulses : 0.0;
  o.cycle_time_s = static_cast<double>(k) * 1e-3;
  return o;
}

class DrillSeeds : public ::testing::TestWithParam<int> {};

TEST_P(DrillSeeds, TwentyMillimetreHoleWithAndWithoutWearCompensation) {
  const int seed = GetParam();
  const Outcome with = run(seed, true);
  const Outcome without = run(seed, false);
  ASSERT_TRUE(with.done) << "not DONE in 200 s; depth " << with.true_depth_mm;
  ASSERT_TRUE(without.done) << "not DONE in 200 s; depth " << without.true_depth_mm;
  const double err_with = with.true_depth_mm - 20.0;
  const double err_without = without.true_depth_mm - 20.0;
  std::printf(
      "[drill] seed %d  WITH wear comp: depth %.4f mm (err %+.4f), est wear %.4f mm, electrode "
      "used %.4f mm, drill %.2f s, shorts %.2f %% of %.0f pulses | WITHOUT: depth %.4f mm (err "
      "%+.4f), electrode "
      "used %.4f mm, drill %.2f s, shorts %.2f %%\n",
      seed, with.true_depth_mm, err_with, with.wear_est_mm, with.electrode_used_mm,
      with.drill_time_s, 100.0 * with.short_fraction, with.pulses, without.true_depth_mm,
      err_without, without.electrode_used_mm, without.drill_time_s, 100.0 * without.short_fraction);
  RecordProperty("depth_error_with_comp_um", static_cast<int>(err_with * 1000.0));
  RecordProperty("depth_error_without_comp_um", static_cast<int>(err_without * 1000.0));
  RecordProperty("short_fraction_permille", static_cast<int>(with.short_fraction * 1000.0));
  RecordProperty("drill_time_ms", static_cast<int>(with.drill_time_s * 1000.0));
  // 20.000 ± 0.02 mm with E1's calibrated effective wear ratio (0.6166, calibrated on seed 100,
  // not on these seeds: docs/blocks.md "Calibrating the wear ratio").
  EXPECT_NEAR(with.true_depth_mm, 20.0, 0.02);
  EXPECT_GT(std::abs(err_without), 20.0 * std::abs(err_with)) << "compensation removes >95 %";
  EXPECT_GT(with.pulses, 1e5);
  EXPECT_LE(with.short_fraction, 0.05);
  EXPECT_LE(without.short_fraction, 0.05);
  // Without compensation the hole falls short by about the electrode wear.
  EXPECT_LT(err_without, -0.5 * without.electrode_used_mm);
}

INSTANTIATE_TEST_SUITE_P(Seeds, DrillSeeds, ::testing::Values(1, 2, 3));

// Feed hold in the middle of a hole: the generator goes off and Z stops at once, nothing erodes
// or wears meanwhile, and on release the cycle goes on to the same accurate depth.
TEST(DrillHold, HoldMidHoleFreezesAndResumesToTheSameDepth) {
  SteppedMachine m(read_file(kConfig), "drill-sim-program.yaml");
  auto read = [&](const char* n) { return m.read(n); };
  m.run_while(200'000, [&] { return read("cycle.drill.depth_reached_mm") < 8.0; });
  ASSERT_EQ(read("cycle.drill.state"), 2.0) << "drilling";

  ASSERT_TRUE(m.hold("cycle.drill.hold"));
  EXPECT_EQ(read("cycle.drill.gen_on"), 0.0) << "generator off in the first held cycle";
  EXPECT_EQ(read("cycle.drill.vz_cmd_mm_s"), 0.0);
  m.run(50);  // the axis comes to rest
  const double depth0 = read("io.depth_mm"), electrode0 = read("io.electrode_mm");
  const double z0 = read("io.z_mm"), estimate0 = read("cycle.drill.depth_reached_mm");
  m.run(2000);  // 2 s held
  EXPECT_EQ(read("io.depth_mm"), depth0) << "nothing eroded while held";
  EXPECT_EQ(read("io.electrode_mm"), electrode0) << "no wear while held";
  EXPECT_NEAR(read("io.z_mm"), z0, 1e-3) << "Z still";
  EXPECT_EQ(read("cycle.drill.depth_reached_mm"), estimate0);
  EXPECT_EQ(read("cycle.drill.state"), 2.0) << "still in DRILL, not restarted";

  ASSERT_TRUE(m.vars.unforce("cycle.drill.hold"));
  m.run_while(400'000, [&] { return read("cycle.drill.state") != 4.0; });
  ASSERT_EQ(read("cycle.drill.state"), 4.0) << "DONE after the release";
  std::printf("[drill] held 2 s at %.3f mm, finished at %.4f mm (true %.4f)\n", estimate0,
              read("cycle.drill.depth_reached_mm"), read("io.depth_mm"));
  EXPECT_NEAR(read("io.depth_mm"), 20.0, 0.02);
}

// A through hole in a 3 mm plate: sparks stop when the front leaves the work; with `through` set
// DeepHoleDrill sees the breakthrough, feeds on overtravel_mm, retracts and ends DONE well before
// the 10 mm it was asked for. The same plate without `through` keeps feeding (a blind-hole cycle
// must never stop early on a dark spell).
struct Through {
  bool done{false};
  bool breakthrough{false};
  double depth_reached_mm{0.0};
  double z_at_done_mm{0.0};
};

Through run_through(bool through) {
  Through t;
  std::string text = read_file(kConfig);
  replace_once(text, "params: {preset: drill, seed: 1}",
               "params: {preset: drill, seed: 1, work_thickness_mm: 3}");
  replace_once(text, "depth_default_mm: 20", "depth_default_mm: 10");
  replace_once(
      text, "      drill.start: true",
      std::string("      drill.start: true\n      drill.through: ") + (through ? "true" : "false"));
  SteppedMachine m(text, "through.yaml");
  auto& vars = m.vars;
  for (std::int64_t k = 0; k < 60'000; ++k) {
    m.run_cycle(k);
    if (vars.read("cycle.drill.breakthrough").value() != 0.0) t.breakthrough = true;
    if (vars.read("cycle.drill.state").value() == 4.0) {
      t.done = true;
      break;
    }
  }
  t.depth_reached_mm = vars.read("cycle.drill.depth_reached_mm").value();
  t.z_at_done_mm = vars.read("io.z_mm").value();
  return t;
}

TEST(DrillThrough, BreakthroughIsDetectedOnlyForThroughHoles) {
  const Through t = run_through(true);
  ASSERT_TRUE(t.done) << "a through hole in a 3 mm plate ends";
  EXPECT_TRUE(t.breakthrough);
  EXPECT_GT(t.depth_reached_mm, 3.0 - 0.2) << "not before the front reached the far side";
  EXPECT_LT(t.depth_reached_mm, 10.0 - 1.0) << "well before the commanded 10 mm";
  const Through blind = run_through(false);
  EXPECT_FALSE(blind.breakthrough);
}

}  // namespace
}  // namespace edm::test
