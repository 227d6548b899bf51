// The controller benchmark's runner (apps/bench/controllers): B7 determinism on short runs, and
// a controller property the benchmark measures.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "controllers/bench.hpp"

namespace edm::bench {
namespace {

const std::string kRoot = EDM_SOURCE_DIR;

// The scenario's variant by name (fails the test if the scenario list changed).
RunSpec spec_of(const std::string& id, std::size_t variant, bool quick = true) {
  for (const Scenario& s : make_scenarios(quick)) {
    if (s.id == id && variant < s.variants.size()) {
      return s.variants[variant].spec;
    }
  }
  ADD_FAILURE() << "no scenario " << id << " variant " << variant;
  return {};
}

void expect_bitwise_equal(const Outcome& a, const Outcome& b) {
  const auto fa = a.fields();
  const auto fb = b.fields();
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t i = 0; i < fa.size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(fa[i].second),
              std::bit_cast<std::uint64_t>(fb[i].second))
        << fa[i].first << ": " << fa[i].second << " vs " << fb[i].second;
  }
  EXPECT_EQ(a.jitter_per_cycle_um, b.jitter_per_cycle_um);
  EXPECT_EQ(a.rab_per_s, b.rab_per_s);
}

TEST(ControllerBench, B7SameSeedGivesIdenticalFiguresAnotherSeedDoesNot) {
  for (const auto& [id, variant] :
       {std::pair<std::string, std::size_t>{"B1", 0}, {"B5", 1}, {"B6a", 1}}) {
    SCOPED_TRACE(id);
    RunSpec spec = spec_of(id, variant);
    spec.limit_s = 4.0;
    spec.seed = 11;
    const Outcome a = run(kRoot, spec);
    const Outcome b = run(kRoot, spec);
    expect_bitwise_equal(a, b);
    EXPECT_GT(a.depth_mm, 0.0) << "the run machined something";
    spec.seed = 12;
    const Outcome c = run(kRoot, spec);
    EXPECT_NE(a.depth_mm, c.depth_mm) << "another seed, other noise";
  }
}

// B1 at full depth (30 mm), seed 1: seed 004's P gap controller reaches the depth; a constant
// feed of 0.75 mm/s (faster than the hole can be eroded once debris slows it past h/d ≈ 15)
// jams the electrode into the work: most pulses are shorts and the depth is never reached.
TEST(ControllerBench, B1PGapControllerReachesDepthConstantFeedJamsInShorts) {
  const auto scenarios = make_scenarios(/*quick=*/false);
  ASSERT_EQ(scenarios.at(0).id, "B1");
  RunSpec p = scenarios[0].variants.at(0).spec;
  RunSpec constant = scenarios[0].variants.at(2).spec;
  ASSERT_NE(constant.config.find("constant-feed"), std::string::npos);
  const Outcome op = run(kRoot, p);
  const Outcome oc = run(kRoot, constant);
  EXPECT_EQ(op.reached, 1.0);
  EXPECT_LT(op.time_to_depth_s, 100.0);
  EXPECT_LT(op.short_pct, 1.0);
  EXPECT_EQ(oc.reached, 0.0) << "constant feed reached 30 mm in " << oc.time_to_depth_s << " s";
  EXPECT_GT(oc.short_pct, 50.0);
  EXPECT_LT(oc.depth_mm, 30.0 - 1.0);
}

const Scenario& scenario(const std::vector<Scenario>& all, const std::string& id) {
  for (const Scenario& s : all) {
    if (s.id == id) {
      return s;
    }
  }
  throw std::runtime_error("no scenario " + id);
}

// B3 (30 mm, flushing × 0.3 from 15 mm), seed 1: the drop reaches the simulator through the
// run's io params and costs the P controller time and arcs against B1 on the same seed; the
// window figures are measured from the drop on.
TEST(ControllerBench, B3FlushingDropSlowsThePControllerAgainstB1) {
  const auto all = make_scenarios(/*quick=*/false);
  RunSpec b1 = scenario(all, "B1").variants.at(0).spec;
  RunSpec b3 = scenario(all, "B3").variants.at(0).spec;
  ASSERT_EQ(b3.config, b1.config);
  ASSERT_GT(b3.flush_drop_mm, 0.0);
  const Outcome o1 = run(kRoot, b1);
  const Outcome o3 = run(kRoot, b3);
  ASSERT_EQ(o1.reached, 1.0);
  ASSERT_EQ(o3.reached, 1.0);  // DeepHoleDrill DONE
  EXPECT_GT(o3.time_s, o1.time_s + 10.0) << "B1 " << o1.time_s << " s, B3 " << o3.time_s << " s";
  EXPECT_GT(o3.arc_pct, o1.arc_pct + 2.0);
  EXPECT_GT(o3.peak_arc_pct, o3.arc_pct) << "windows were measured after the drop";
}

// B4, seed 1: the calibrated WallFinish leaves the mean wall radius within ±5 µm of initial +
// 50 µm and the 64 bins within 5 µm of each other (as tests/programs does on the plant
// directly); the bench's figures are measured against the initial bins of the same run.
TEST(ControllerBench, B4CalibratedWallFinishHitsTheRadiusRoundly) {
  const auto all = make_scenarios(/*quick=*/true);
  const Outcome o = run(kRoot, scenario(all, "B4").variants.at(0).spec);
  ASSERT_EQ(o.reached, 1.0) << "WallFinish did not reach DONE in " << o.time_s << " s";
  EXPECT_NEAR(o.wall_err_um, 0.0, 5.0);
  EXPECT_GT(o.circularity_um, 0.0);
  EXPECT_LT(o.circularity_um, 5.0);
  EXPECT_LE(std::abs(o.wall_worst_um), 5.0);
}

// B5 quick (15 s = 10 jump cycles), seed 1: the outcomes of the voltage servo (variant 0) and of
// variant `v`, whose config names `tag`.
std::pair<Outcome, Outcome> b5_servo_and(std::size_t v, const std::string& tag) {
  const auto all = make_scenarios(/*quick=*/true);
  const Scenario& b5 = scenario(all, "B5");
  EXPECT_EQ(b5.variants.size(), 4U);
  const RunSpec& spec = b5.variants.at(v).spec;
  EXPECT_NE(spec.config.find(tag), std::string::npos) << tag;
  return {run(kRoot, b5.variants.at(0).spec), run(kRoot, spec)};
}

// B5 (quick, 15 s = 10 jump cycles), seed 1: seed 002's ILC, its cycle driven by the bench's
// forced jump, holds the z-jitter of the last cycles well below the voltage servo's at a
// comparable removal rate (issue 7: "z-jitter falls … compared with the P/integral controller").
TEST(ControllerBench, B5IlcJitterBelowTheVoltageServo) {
  const auto [servo, ilc] = b5_servo_and(2, "sink-ilc");
  ASSERT_EQ(ilc.jitter_per_cycle_um.size(), servo.jitter_per_cycle_um.size());
  EXPECT_LT(ilc.jitter_last_um, 0.5 * servo.jitter_last_um)
      << "ILC " << ilc.jitter_last_um << " µm, servo " << servo.jitter_last_um << " µm";
  EXPECT_GT(ilc.jitter_last_um, 0.0) << "the ILC's Z moved within the cycles";
  EXPECT_GT(ilc.mrr_mm3_min, 0.8 * servo.mrr_mm3_min);
  EXPECT_LT(ilc.ratio_short_pct, 1.0);
}

// Seed 001's claims on B5: the main loop's y_v tracks its reference and arcs stay suppressed
// (here: stable arcs at the voltage servo's level, transient arcs within 1.5x of it).
TEST(ControllerBench, B5StrTracksItsReferenceAndKeepsArcsAtTheBaselinesLevel) {
  const auto [servo, str] = b5_servo_and(1, "sink-str");
  EXPECT_TRUE(std::isnan(servo.loop_err_rms)) << "the servo has no y_v loop";
  ASSERT_FALSE(std::isnan(str.loop_err_rms));
  EXPECT_NEAR(str.loop_y_mean, str.loop_ref_mean, 0.04) << "no bias from the approach";
  EXPECT_LT(str.loop_err_rms, 0.1);
  EXPECT_GT(str.loop_ref_mean, 0.9) << "the reference decision found the gap good";
  EXPECT_LE(str.ratio_sarc_pct, 2.0 * servo.ratio_sarc_pct + 0.005);
  EXPECT_LE(str.ratio_tarc_pct, 1.5 * servo.ratio_tarc_pct);
  // Held through the jump and the approach, it removes about as much as the servo (quick runs:
  // a few per cent more; 45 s runs: a few per cent less, docs/benchmarks.md B5).
  EXPECT_GT(str.mrr_mm3_min, 0.9 * servo.mrr_mm3_min);
  EXPECT_LT(str.jitter_um, 0.5 * servo.jitter_um) << "Us is not disturbed by the approach";
}

// The paper's comparison (Fig. 1): the ILC learning from the integral controller (the voltage
// servo) it replaces. Until the ILC takes over the machine is the servo's, bit for bit; then
// the ILC's z-jitter falls over the cycles while the servo's stays where it was.
TEST(ControllerBench, B5IlcLearningFromTheIntegralControllerLowersItsJitterOverTheCycles) {
  const auto [servo, warm] = b5_servo_and(3, "sink-ilc-warm");
  const auto& js = servo.jitter_per_cycle_um;
  const auto& jw = warm.jitter_per_cycle_um;
  ASSERT_EQ(jw.size(), js.size());
  ASSERT_GE(jw.size(), 8U);
  // Cycles 0-2: the servo drives (cycles 1 and 2 are recorded, warm_cycles 2).
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_EQ(jw[c], js[c]) << "cycle " << c << ": the servo's machine until the take-over";
  }
  const std::size_t last = jw.size() - 1;
  EXPECT_LT(jw[last], 0.3 * jw[2]) << "the ILC's jitter fell over the cycles";
  EXPECT_LT(jw[last], 0.3 * js[last]) << "and stays below the integral controller's";
  EXPECT_GT(js[last], 0.7 * js[2]) << "the integral controller does not learn";
  EXPECT_LE(jw[4], jw[3] * 1.05) << "falling, not jumping";
  EXPECT_GT(warm.mrr_mm3_min, 0.8 * servo.mrr_mm3_min);
}

// B6, seed 000's four cases at full length (120 s; case 4 240 s), and B6e (flushing lost under
// the nozzle, then back), on one seed that is not among the 20 benchmark seeds: without
// control the wire breaks in every case (in case 4 at the cavity's far wall, not before); with
// the self-tuning fuzzy controller and grey predictor (Table 5's row per case) it does not, and
// Rab's 1 s means come into ±0.1 of the set point and stay there to the end of the run (in
// cases 2 and 3 already in the scoring window after 45 s; case 1 is at the edge of the band
// over 20 seeds, and case 4 takes ≈ 80 s after the wall: docs/benchmarks.md, B6). Without the
// predictor case 1 breaks as without control: the paper's argument for the predictor. Without
// the start-up transient it breaks too (issue 20).
TEST(ControllerBench, B6SelfTuningFuzzyKeepsTheWireWhereFixedSettingsBreakIt) {
  const auto all = make_scenarios(/*quick=*/false);
  for (const char* id : {"B6a", "B6b", "B6c", "B6d", "B6e"}) {
    SCOPED_TRACE(id);
    const Scenario& s = scenario(all, id);
    ASSERT_EQ(s.variants.at(0).name, "no control (fixed settings)");
    ASSERT_EQ(s.variants.at(1).name, "STFPI + grey as printed (p 37), from the first sample");
    RunSpec fixed = s.variants[0].spec;
    RunSpec stfpi = s.variants[1].spec;
    fixed.seed = stfpi.seed = 101;
    const Outcome of = run(kRoot, fixed);
    const Outcome oc = run(kRoot, stfpi);
    EXPECT_EQ(of.wire_broken, 1.0);
    EXPECT_LT(of.break_time_s, 60.0);
    EXPECT_EQ(oc.wire_broken, 0.0) << "broke at " << oc.break_time_s << " s";
    EXPECT_GT(oc.depth_mm, 1.0) << "it still cuts";
    EXPECT_LT(oc.rab_in_band_s, stfpi.limit_s - 60.0)
        << "Rab settles into ±0.1 for the last minute";
    const std::string which = id;
    if (which == "B6b" || which == "B6c") {
      EXPECT_LE(oc.rab_above_max, kRabBand);
      EXPECT_LE(oc.rab_below_max, kRabBand);
    }
    if (which == "B6a") {
      ASSERT_EQ(s.variants.at(5).name, "STFPI, no predictor");
      RunSpec nogrey = s.variants[5].spec;
      nogrey.seed = 101;
      EXPECT_EQ(run(kRoot, nogrey).wire_broken, 1.0);
      // Issue 20: what saves the wire in case 1 is the start-up transient (the predictor's
      // extrapolation of the filter's rise drives u and v to their upper limits in the first
      // second). Held for those 200 samples at Table 4's settings, the paper's controller with
      // Table 5's gains then holds Rab near 0.73, at the rupture level, and the wire breaks.
      ASSERT_EQ(s.variants.at(3).name,
                "STFPI + grey, start-up excluded: held 200 samples at the fixed settings");
      RunSpec held = s.variants[3].spec;
      held.seed = 101;
      const Outcome oh = run(kRoot, held);
      EXPECT_EQ(oh.wire_broken, 1.0);
      EXPECT_GT(oh.break_time_s, of.break_time_s) << "later than without control";
    }
    if (which == "B6d") {
      EXPECT_GT(of.break_time_s, 40.0) << "the fixed settings hold the 30 mm part up to the wall";
    }
  }
}

}  // namespace
}  // namespace edm::bench
