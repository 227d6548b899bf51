// WallFinish on the simulated drilling machine
// (config/machines/finish-sim-program.yaml): finish the wall of the preset's
// initial hole (Ø1.1 mm, tube Ø1.0 mm) with positive polarity and a growing
// orbit; measure the mean wall radius and all wall bins against the target.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "edm/blocks/register.hpp"
#include "edm/programs/register.hpp"
#include "edm/runtime/clock.hpp"
#include "edm/runtime/config.hpp"
#include "edm/runtime/loopback_driver.hpp"
#include "edm/runtime/runtime.hpp"
#include "edm/sim/plant.hpp"
#include "edm/sim/sim_driver.hpp"
#include "sim_machine.hpp"

namespace edm::test {
namespace {

using namespace std::chrono_literals;

const std::string kConfig =
    std::string(EDM_SOURCE_DIR) + "/config/machines/finish-sim-program.yaml";

struct Finish {
  bool done{false};
  bool gen_before_positive{false};
  double r_initial_mm{0.0};
  double r_mean_mm{0.0};
  double r_min_mm{0.0};
  double r_max_mm{0.0};
  double offset_mm{0.0};
  double time_s{0.0};
  double short_fraction{0.0};
};

Finish run(int seed, double final_offset_mm, double limit_s) {
  Finish f;
  std::string text = read_file(kConfig);
  replace_once(text, "seed: 1", "seed: " + std::to_string(seed));
  replace_once(text, "finish.final_offset_mm: 0.05",
               "finish.final_offset_mm: " + std::to_string(final_offset_mm));
  SteppedMachine m(text, "finish-sim-program.yaml");
  auto& vars = m.vars;
  const sim::Plant& plant = dynamic_cast<sim::SimDriver&>(m.runtime->driver()).plant();
  f.r_initial_mm = plant.wall_bin_radius_mm(0);
  double shorts = 0.0;
  double pulses = 0.0;
  const auto cycles = static_cast<std::int64_t>(limit_s * 1000.0);
  std::int64_t k = 0;
  for (; k < cycles; ++k) {
    m.run_cycle(k);
    if (vars.read("cycle.finish.gen_on").value() != 0.0 &&
        (vars.read("cycle.finish.polarity_positive").value() == 0.0 ||
         vars.read("io.polarity_positive").value() == 0.0)) {
      f.gen_before_positive = true;
    }
    if (vars.read("cycle.finish.state").value() == 2.0) {
      shorts += vars.read("io.n_short").value();
      pulses += vars.read("io.td_count").value() + vars.read("io.n_open").value() +
                vars.read("io.n_short").value();
    }
    if (vars.read("cycle.finish.state").value() == 4.0) {
      f.done = true;
      break;
    }
  }
  f.time_s = static_cast<double>(k) * 1e-3;
  f.offset_mm = vars.read("cycle.finish.offset_mm").value();
  f.r_mean_mm = vars.read("io.wall_radius_mm").value();
  f.r_min_mm = 1e9;
  f.r_max_mm = -1e9;
  for (std::size_t j = 0; j < sim::Plant::kWallBins; ++j) {
    f.r_min_mm = std::min(f.r_min_mm, plant.wall_bin_radius_mm(j));
    f.r_max_mm = std::max(f.r_max_mm, plant.wall_bin_radius_mm(j));
  }
  f.short_fraction = pulses > 0.0 ? shorts / pulses : 0.0;
  return f;
}

void report(const char* tag, int seed, double final_offset_mm, const Finish& f, double target) {
  std::printf(
      "[wall_finish_sim] %s seed %d final_offset %.4f: done %d in %.1f "
      "s | wall r: initial "
      "%.4f, mean %.4f (target %.4f, err %+.1f um), bins min %.4f max "
      "%.4f (spread %.1f um, "
      "worst err %+.1f / %+.1f um), shorts %.2f %%\n",
      tag, seed, final_offset_mm, f.done ? 1 : 0, f.time_s, f.r_initial_mm, f.r_mean_mm, target,
      (f.r_mean_mm - target) * 1e3, f.r_min_mm, f.r_max_mm, (f.r_max_mm - f.r_min_mm) * 1e3,
      (f.r_min_mm - target) * 1e3, (f.r_max_mm - target) * 1e3, 100.0 * f.short_fraction);
}

class FinishSeeds : public ::testing::TestWithParam<int> {};

// Issue 4: +0.05 mm of wall radius, ±5 µm all round. Since issue 20 (eq. 21 live: the last
// revolutions' small Tdm makes the last steps small) with no calibrated offset: the final offset
// is the programmed growth itself, 0.05 mm; every wall bin is asserted within ±5 µm.
TEST_P(FinishSeeds, WallRadiusPlusFiftyMicronsAllRound) {
  const int seed = GetParam();
  const Finish f = run(seed, 0.05, 120.0);
  const double target = f.r_initial_mm + 0.05;
  report("uncalibrated", seed, 0.05, f, target);
  RecordProperty("wall_mean_err_nm", static_cast<int>((f.r_mean_mm - target) * 1e6));
  RecordProperty("wall_min_err_nm", static_cast<int>((f.r_min_mm - target) * 1e6));
  RecordProperty("wall_max_err_nm", static_cast<int>((f.r_max_mm - target) * 1e6));
  ASSERT_TRUE(f.done);
  EXPECT_FALSE(f.gen_before_positive);
  EXPECT_NEAR(f.offset_mm, 0.05, 1e-12);
  EXPECT_NEAR(f.r_min_mm, target, 0.005);
  EXPECT_NEAR(f.r_max_mm, target, 0.005);
  EXPECT_NEAR(f.r_mean_mm, target, 0.005);
}

INSTANTIATE_TEST_SUITE_P(Seeds, FinishSeeds, ::testing::Values(1, 2, 3));

// The offset calibrated before issue 20 (0.048 mm, for the clamped 2 µm steps). Reported;
// asserted loosely.
TEST(WallFinishSim, FormerlyCalibratedFinalOffset) {
  const Finish f = run(1, 0.048, 120.0);
  const double target = f.r_initial_mm + 0.05;
  report("calibrated before issue 20", 1, 0.048, f, target);
  ASSERT_TRUE(f.done);
  EXPECT_FALSE(f.gen_before_positive);
  EXPECT_NEAR(f.r_mean_mm, target, 0.010);
}

// Feed hold in the orbit: the generator goes off and the electrode stays still, nothing erodes
// and no revolution counts meanwhile; on release the finish ends within its ±5 µm as without.
TEST(FinishHold, HoldMidOrbitFreezesAndResumes) {
  SteppedMachine m(read_file(kConfig), "finish-sim-program.yaml");
  const sim::Plant& plant = dynamic_cast<sim::SimDriver&>(m.runtime->driver()).plant();
  const double target = plant.wall_bin_radius_mm(0) + 0.05;
  auto read = [&](const char* n) { return m.read(n); };
  m.run_while(120'000, [&] { return read("cycle.finish.revolutions") < 5.0; });
  ASSERT_EQ(read("cycle.finish.state"), 2.0) << "orbiting";

  ASSERT_TRUE(m.hold("cycle.finish.hold"));
  EXPECT_EQ(read("cycle.finish.gen_on"), 0.0) << "generator off in the first held cycle";
  m.run(200);  // the axes come to rest
  const double r0 = read("io.wall_radius_mm"), x0 = read("io.x_mm"), y0 = read("io.y_mm");
  const double revs0 = read("cycle.finish.revolutions");
  m.run(2000);  // 2 s held
  EXPECT_EQ(read("io.wall_radius_mm"), r0) << "nothing eroded while held";
  EXPECT_NEAR(read("io.x_mm"), x0, 1e-3);
  EXPECT_NEAR(read("io.y_mm"), y0, 1e-3);
  EXPECT_EQ(read("cycle.finish.revolutions"), revs0);
  EXPECT_EQ(read("cycle.finish.state"), 2.0);

  ASSERT_TRUE(m.vars.unforce("cycle.finish.hold"));
  m.run_while(240'000, [&] { return read("cycle.finish.state") != 4.0; });
  ASSERT_EQ(read("cycle.finish.state"), 4.0) << "DONE after the release";
  double r_min = 1e9, r_max = -1e9;
  for (std::size_t j = 0; j < sim::Plant::kWallBins; ++j) {
    r_min = std::min(r_min, plant.wall_bin_radius_mm(j));
    r_max = std::max(r_max, plant.wall_bin_radius_mm(j));
  }
  std::printf("[wall_finish_sim] held 2 s after %g revolutions; bins %.4f..%.4f (target %.4f)\n",
              revs0, r_min, r_max, target);
  EXPECT_NEAR(r_min, target, 0.005);
  EXPECT_NEAR(r_max, target, 0.005);
}

// An orbit that never sparks (the electrode 3 mm above the work: no wall, no front) trips the
// no-spark timeout: a block fault, the machine goes to FAULT, the finish is abandoned.
TEST(FinishNoSpark, AnOrbitThatNeverSparksFaultsAfterTheTimeout) {
  std::string text = read_file(kConfig);
  replace_once(text, "initial_depth_mm: 2}", "initial_depth_mm: 2, start_gap_um: 5000}");
  replace_once(text, "spark_out_revs: 4,", "spark_out_revs: 4, no_spark_timeout: 3s,");
  SteppedMachine m(text, "finish-sim-program.yaml");
  auto& r = m.runtime;
  auto& vars = m.vars;
  std::int64_t k = 0, orbit_from = -1;
  for (; k < 20'000 && !rt::is_safe_state(r->machine().state()); ++k) {
    m.run_cycle(k);
    if (orbit_from < 0 && vars.read("cycle.finish.state").value() == 2.0) orbit_from = k;
    EXPECT_EQ(vars.read("io.td_count").value(), 0.0) << "no spark at all";
  }
  ASSERT_GE(orbit_from, 0);
  EXPECT_EQ(r->machine().state(), rt::MachineState::kFault);
  EXPECT_EQ(r->machine().last_cause(), rt::AlarmCode::kBlockFault);
  EXPECT_EQ(vars.read("cycle.finish.no_spark").value(), 1.0);
  const double after_s = static_cast<double>(k - orbit_from) * 1e-3;
  EXPECT_GE(after_s, 3.0) << "not before the timeout";
  EXPECT_LT(after_s, 3.1) << "at the timeout";
}

}  // namespace
}  // namespace edm::test
