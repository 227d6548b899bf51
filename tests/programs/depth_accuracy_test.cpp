// Seed 004's headline, depth accuracy, as a property of the method (issue 20 f): a blind hole
// drilled by the shipped drill machine (config/machines/drill-sim.yaml, one set of parameters)
// from a G-code program interpreted as edmhmi does, at 3, 8, 15, 25 and 30 mm, on scoring seeds
// (1-5 here; EDM_DEPTH_SEEDS=1-20 for the benchmark table). The truth is the simulator's hole
// depth (io.depth_mm), not the controller's estimate.
//   DepthAccuracy      as shipped, with EdmJob's depth probe (the depth measured by touching the
//                      bottom and the surface, the last 0.1 mm drilled from the measurement;
//                      contact_offset_um calibrated on seeds 1000-1004): ±10 µm, the issue's
//                      target; and the probe's measured depth within ±6 µm of the truth.
//   DepthAccuracyEq8   the paper's method alone (probe_depth off: eq. 8's wear estimate, E1's θ
//                      and drill.spark_gap_offset_um calibrated on seeds 1000-1004): ±30 µm. The
//                      ±10 µm target is NOT met that way: the residual (up to ≈ +24 µm at 15-25 mm)
//                      is the electrode's wear per depth varying by ±0.2 % with depth (wall
//                      sparks, arcs), which one wear ratio cannot follow (docs/benchmarks.md
//                      "Depth accuracy" decomposes it with the printed truth).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_config.hpp"
#include "job_runner.hpp"

namespace edm::test {
namespace {

std::string blind_hole(double depth_mm) {
  char line[64];
  std::snprintf(line, sizeof line, "G01 Z-%.3f F60\n", depth_mm);
  return std::string("G17 G21 G90\nG00 Z0.5\nM03 M08\nE1\n") + line +
         "E0\nG00 Z5.0\nM05 M09\nM30\n";
}

struct Hole {
  bool finished{false};
  double depth_mm{0.0};
  double time_s{0.0};
  double planned_travel_mm{0.0};  // lz' of the drilling block (eq. 11)
  double travel_mm{0.0};          // how far Z went down from the block's start
  // Where the residual comes from (the simulator's truth at the touch and at the end of DRILL):
  double gap_touch_um{0.0}, gap_end_um{0.0};   // the frontal gap
  double wear_true_mm{0.0}, wear_est_mm{0.0};  // electrode wear in DRILL: true, eq. 8's
  double td_rms_us{0.0};                       // RMS(Td − Tdr) while drilling (the ISE's e)
  double measured_mm{0.0};                     // the depth probe's measured depth (0: none)
  std::int64_t probe_failures{0};
};

// EDM_DEPTH_CONFIG=PATH runs another config (an experiment: another Kg, another calibration).
std::string machine_config() {
  const char* p = std::getenv("EDM_DEPTH_CONFIG");
  return p != nullptr ? p : std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml";
}

Hole drill(int seed, double depth_mm, bool probe) {
  const std::string cfg = machine_config();
  hmi::GcodeOptions o;
  o.start_mm = {0, 0, 0.1};
  const auto g = hmi::interpret_gcode(blind_hole(depth_mm), "blind.nc",
                                      machining::read_machine_tables(cfg), o);
  EXPECT_TRUE(g.ok()) << (g.ok() ? "" : g.messages()[0]);
  Hole h;
  double z_start = 0.0, z_min = 1e9, state = 0.0, electrode0 = 0.0;
  bool drilling = false, touched = false;
  for (const machining::MotionBlock& b : g.blocks) {
    if (b.kind == machining::MotionKind::kDrill) h.planned_travel_mm = b.z_travel_mm;
  }
  double td_sq = 0.0;
  std::int64_t td_n = 0;
  const JobResult j = run_job(
      seed, g.blocks, o.start_mm, cfg,
      [&](const rt::VariableRegistry& v) {
        const double st = v.read("cnc.job.drill.state").value();
        if (st == 2.0 && state != 2.0 && !touched) {  // the touch (of the first drilling)
          touched = true;
          h.gap_touch_um = v.read("io.true_gap_um").value();
          electrode0 = v.read("io.electrode_mm").value();
        }
        if (st == 2.0) {
          h.gap_end_um = v.read("io.true_gap_um").value();
          h.wear_true_mm = electrode0 - v.read("io.electrode_mm").value();
          h.wear_est_mm = v.read("cnc.job.drill.wear.wear_mm").value();
        }
        if (st == 2.0 && v.read("cnc.job.drill.td.valid").value() != 0.0) {
          const double e =
              v.read("cnc.job.drill.td.td_us").value() - v.read("cnc.job.drill.tdr_us").value();
          td_sq += e * e;
          ++td_n;
        }
        h.measured_mm = v.read("cnc.job.probe.measured_depth_mm").value();
        h.probe_failures = static_cast<std::int64_t>(v.read("cnc.job.probe.failures").value());
        state = st;
        const bool now = st != 0.0;
        const double z = v.read("io.z_mm").value();
        if (now && !drilling) z_start = z;
        drilling = drilling || now;
        if (st == 2.0) z_min = std::min(z_min, z);  // the drilling's own travel (not the touches)
      },
      [probe](rt::Runtime& r) {
        ASSERT_TRUE(r.variables().write("cnc.job.probe.enable", rt::ParamValue::of_bool(probe)));
      });
  h.finished = j.finished;
  h.depth_mm = j.depth_mm;
  h.time_s = j.time_s;
  h.travel_mm = z_start - z_min;
  h.td_rms_us = td_n > 0 ? std::sqrt(td_sq / static_cast<double>(td_n)) : 0.0;
  return h;
}

std::vector<int> seeds_from_env(const char* name, std::vector<int> fallback) {
  const char* s = std::getenv(name);
  if (s == nullptr) return fallback;
  std::vector<int> out;
  int a = 0, b = 0;
  if (std::sscanf(s, "%d-%d", &a, &b) == 2) {
    for (int k = a; k <= b; ++k) out.push_back(k);
  }
  return out;
}

// Scoring seeds 1-5; one under a sanitizer (about 10x slower: five seeds of a 30 mm hole would
// pass ctest's 300 s timeout there, and the sanitizers look for memory errors, not figures).
#if defined(EDM_UNDER_SANITIZER)
const std::vector<int> kScoringSeeds = {1};
#else
const std::vector<int> kScoringSeeds = {1, 2, 3, 4, 5};
#endif

// Drills each scoring seed's hole at the parameter's depth; err_bound_mm on the truth.
void score(double depth, bool probe, double err_bound_mm) {
  const std::vector<int> seeds = seeds_from_env("EDM_DEPTH_SEEDS", kScoringSeeds);
  if (const char* d = std::getenv("EDM_DEPTH_ONLY")) {  // experiments: one depth
    if (depth != 3.0) GTEST_SKIP() << "EDM_DEPTH_ONLY";
    depth = std::atof(d);
  }
  double sum = 0.0, worst = 0.0;
  for (const int seed : seeds) {
    const Hole h = drill(seed, depth, probe);
    ASSERT_TRUE(h.finished) << depth << " mm, seed " << seed;
    const double err_um = (h.depth_mm - depth) * 1000.0;
    std::printf(
        "[depth%s] %5.1f mm seed %4d: %8.4f mm (%+6.1f um) in %.1f s; Z travel %.3f mm, "
        "planned lz' %.3f mm; gap touch %.1f end %.1f um, wear true %.4f est %.4f mm; "
        "RMS(Td-Tdr) %.2f us; measured %.4f mm (%+.1f um), probe failures %lld\n",
        probe ? "" : "-eq8", depth, seed, h.depth_mm, err_um, h.time_s, h.travel_mm,
        h.planned_travel_mm, h.gap_touch_um, h.gap_end_um, h.wear_true_mm, h.wear_est_mm,
        h.td_rms_us, h.measured_mm, (h.measured_mm - h.depth_mm) * 1000.0,
        static_cast<long long>(h.probe_failures));
    sum += err_um;
    if (std::abs(err_um) > std::abs(worst)) worst = err_um;
    EXPECT_NEAR(h.depth_mm, depth, err_bound_mm) << depth << " mm, seed " << seed;
    if (probe) {
      EXPECT_EQ(h.probe_failures, 0);
      EXPECT_NEAR(h.measured_mm, h.depth_mm, 0.006) << "the measurement against the truth";
    } else {
      // Eq. 9-11 and eq. 8 agree: Z travels the planned lz' (the wear counted once). (With the
      // probe the hole is drilled in two parts, the second from the measurement.)
      EXPECT_NEAR(h.travel_mm, h.planned_travel_mm, 0.05) << depth << " mm, seed " << seed;
    }
  }
  std::printf("[depth%s] %5.1f mm: mean %+6.1f um, worst %+6.1f um over %zu seeds\n",
              probe ? "" : "-eq8", depth, sum / static_cast<double>(seeds.size()), worst,
              seeds.size());
}

std::string depth_name(const ::testing::TestParamInfo<double>& p) {
  return std::to_string(static_cast<int>(p.param)) + "mm";
}

class DepthAccuracy : public ::testing::TestWithParam<double> {};

TEST_P(DepthAccuracy, ProbedBlindHoleEndsWithinTenMicrometres) { score(GetParam(), true, 0.010); }

INSTANTIATE_TEST_SUITE_P(Depths, DepthAccuracy, ::testing::Values(3.0, 8.0, 15.0, 25.0, 30.0),
                         depth_name);

class DepthAccuracyEq8 : public ::testing::TestWithParam<double> {};

TEST_P(DepthAccuracyEq8, BlindHoleEndsWithinThirtyMicrometres) { score(GetParam(), false, 0.030); }

INSTANTIATE_TEST_SUITE_P(Depths, DepthAccuracyEq8, ::testing::Values(3.0, 8.0, 15.0, 25.0, 30.0),
                         depth_name);

}  // namespace
}  // namespace edm::test
