// Gap-controlled drilling blocks with eq. 9-11 wear pre-compensation, rapids while armed, the
// G160 orbit-finishing cycle and the soft limits.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

using machining::Vec3;

// Seed 004 eq. (8)-(11) written out with explicit rates and the two cross-sections, independently
// of the library: Vd = MRRe/A_e (8), the hole bottom advances at MRRw/A_hole so
// Tw = lz/(MRRw/A_hole) (9), δ = Vd·Tw (10), and the Z travel is the block's length + δ (11);
// θ = MRRe/MRRw. lz is the depth eroded (below the work surface Z0), `block` the whole Z move.
double precompensated_travel(double block, double lz, double theta, double area_ratio) {
  const double a_e = std::numbers::pi * (0.5 * 0.5 - 0.15 * 0.15);  // Ø1.0/0.3 tube, mm²
  const double a_hole = area_ratio * a_e;
  const double mrr_w = 2.7;  // mm³/s, any value
  const double mrr_e = theta * mrr_w;
  const double tw = lz / (mrr_w / a_hole);  // (9)
  const double delta = (mrr_e / a_e) * tw;  // (10)
  return block + delta;                     // (11)
}

TEST(GcodeDrill, G01DownWhileArmedIsAGapControlledDrillBlock) {
  const GcodeResult r = interpret("G00 X3 Y4 Z0.5\nE1\nG01 Z-20 F60\nM30");
  ASSERT_TRUE(r.ok()) << joined(r);
  const auto d = of_kind(r.blocks, MotionKind::kDrill);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].target, (Vec3{3, 4, -20}));  // nominal bottom
  // 0.5 mm of air above the surface, 20 mm eroded: wear planned for the 20 mm only.
  EXPECT_NEAR(d[0].z_travel_mm, precompensated_travel(20.5, 20.0, 0.6, 1.25), 1e-9);
  EXPECT_NEAR(d[0].z_travel_mm, 20.5 + 0.6 * 1.25 * 20.0, 1e-9);
  EXPECT_DOUBLE_EQ(d[0].feed_mm_s, 1.0);  // F caps the gap-controlled speed
  EXPECT_EQ(d[0].condition, 1);
  EXPECT_EQ(d[0].line, 3);
  EXPECT_EQ(d[0].col, 1);
  EXPECT_EQ(r.drill_blocks, 1);
  EXPECT_NEAR(r.drill_depth_mm, 20.0, 1e-9);
  EXPECT_NEAR(r.electrode_wear_mm, 0.6 * 1.25 * 20.0, 1e-9);
}

TEST(GcodeDrill, UsesTheArmedConditionsWearRatio) {
  const auto d = of_kind(blocks_of("E2\nG91 G01 Z-4 F30\nZ-6"), MotionKind::kDrill);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_NEAR(d[0].z_travel_mm, precompensated_travel(4.0, 4.0, 0.05, 1.0), 1e-9);
  EXPECT_NEAR(d[1].z_travel_mm, precompensated_travel(6.0, 6.0, 0.05, 1.0), 1e-9);
  // A drilling block ends back at its start point (the runtime retracts out of the hole and
  // returns there), so the incremental second block starts at Z0 again.
  EXPECT_DOUBLE_EQ(d[1].target.z, -6.0);
  EXPECT_EQ(d[1].condition, 2);
}

TEST(GcodeDrill, EndsWhereItBegan) {
  const auto b = blocks_of("G00 X3 Y4 Z0.5\nE1\nG01 Z-5 F60\nE0\nG91 G00 Z1\nX1");
  const auto r = of_kind(b, MotionKind::kRapid);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[1].target, (Vec3{3, 4, 1.5}));  // from Z0.5, not from the hole bottom at Z-5
  EXPECT_EQ(r[2].target, (Vec3{4, 4, 1.5}));
}

TEST(GcodeDrill, NotADrillWhenDisarmedMovingUpOrSideways) {
  const auto b = blocks_of("G01 Z-5 F60\nE1\nG01 Z2\nX5\nE0\nZ-3");
  ASSERT_EQ(b.size(), 6u);
  EXPECT_EQ(b[0].kind, MotionKind::kLinear);  // not armed yet
  EXPECT_EQ(b[2].kind, MotionKind::kLinear);  // up, away from the work
  EXPECT_EQ(b[3].kind, MotionKind::kLinear);  // sideways at constant Z
  EXPECT_EQ(b[5].kind, MotionKind::kLinear);  // disarmed
  EXPECT_EQ(of_kind(b, MotionKind::kDrill).size(), 0u);
}

TEST(GcodeDrill, RapidsNeverDrillEvenWhenArmed) {
  const auto b = blocks_of("E1\nG00 Z-5");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].kind, MotionKind::kRapid);
  EXPECT_EQ(b[1].z_travel_mm, 0.0);
}

TEST(GcodeDrill, MustBeStraight) {
  EXPECT_EQ(first_error("E1\nG01 X1 Z-5 F60"),
            "t.nc:2:5: a drilling block (G01 toward -Z with E1 armed) must not move X or Y: drill "
            "straight, then move");
  // Repeating the current X is not a move.
  EXPECT_EQ(of_kind(blocks_of("E1\nG01 X0 Y0 Z-5 F60"), MotionKind::kDrill).size(), 1u);
}

TEST(GcodeDrill, PrecompensatedTravelMustStayInsideTheZLimits) {
  // Nominal −40 is inside −60..20, but the Z axis travels 40 + 0.6·1.25·40 = 70 mm, to −70.
  EXPECT_EQ(
      first_error("E1\nG01 Z-40 F60"),
      "t.nc:2:5: drilling with wear pre-compensation moves Z to -70.000 mm (nominal -40.000 - "
      "wear 30.000 mm), beyond the Z soft limit (-60.000..20.000 mm)");
  EXPECT_TRUE(interpret("E1\nG01 Z-34.2857142857 F60\nM30").ok());  // travel 60: at the limit
}

TEST(GcodeSoftLimits, EndPointsOutsideTheAxesAreRefusedAtTheirWord) {
  EXPECT_EQ(first_error("G00 X50 Y101"),
            "t.nc:1:9: Y 101.000 mm is beyond the Y soft limit (-100.000..100.000 mm)");
  EXPECT_EQ(first_error("G00 Z21"),
            "t.nc:1:5: Z 21.000 mm is beyond the Z soft limit (-60.000..20.000 mm)");
  EXPECT_EQ(first_error("G00 X90\nG91 G01 X20 F10"),
            "t.nc:2:9: X 110.000 mm is beyond the X soft limit (-100.000..100.000 mm)");
  EXPECT_TRUE(interpret("G00 X100 Y-100 Z20\nZ-60\nM30").ok());
  // Axes missing from the table are unlimited.
  machining::MachineTables t;
  EXPECT_TRUE(interpret_gcode("G00 X5000 Z-900\nM30", "u.nc", t).ok());
}

TEST(GcodeOrbit, G160FinishesAboutTheCurrentPoint) {
  const auto b = blocks_of("G00 X-20 Y10 Z0.5\nE1\nG01 Z-15 F60\nG00 Z-14.8\nE2\nG160 R0.55 F30");
  const auto o = of_kind(b, MotionKind::kOrbitFinish);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0].centre, (Vec3{-20, 10, -14.8}));
  EXPECT_EQ(o[0].target, (Vec3{-20, 10, -14.8}));  // back at the centre afterwards
  EXPECT_DOUBLE_EQ(o[0].final_radius_mm, 0.55);
  EXPECT_DOUBLE_EQ(o[0].feed_mm_s, 0.5);
  EXPECT_EQ(o[0].condition, 2);
  EXPECT_EQ(o[0].line, 6);
  EXPECT_EQ(o[0].col, 1);
  // E in the same block arms before the cycle runs.
  EXPECT_EQ(of_kind(blocks_of("G160 R1 E2 F30"), MotionKind::kOrbitFinish).size(), 1u);
}

TEST(GcodeOrbit, WordsArmingAndPolarity) {
  EXPECT_EQ(first_error("E2\nG160 F30"), "t.nc:2:1: G160 needs R (the final hole radius, mm)");
  EXPECT_EQ(first_error("E2\nG160 R0 F30"), "t.nc:2:6: final radius 'R0' must be > 0 mm");
  EXPECT_EQ(first_error("G160 R1 F30"),
            "t.nc:1:1: G160 needs an armed condition: select a positive-polarity finishing "
            "condition with E<n> first");
  EXPECT_EQ(first_error("E1\nG160 R1 F30"),
            "t.nc:2:1: G160 orbit finishing needs a positive-polarity condition; E1 'drill-rough' "
            "is negative");
  EXPECT_EQ(first_error("E2\nG160 R1 X1 F30"), "t.nc:2:9: 'X1' cannot share a block with 'G160'");
  EXPECT_EQ(first_error("E2\nG160 R1"),
            "t.nc:2:1: G160 needs a feed rate: program F (mm/min) before the first feed move");
  EXPECT_EQ(first_error("G00 X99.8\nE2\nG160 R0.5 F30"),
            "t.nc:3:1: G160 orbit of radius 0.500 mm: X 100.300 mm is beyond the X soft limit "
            "(-100.000..100.000 mm)");
}

TEST(GcodeOrbit, IsNotModal) {
  const auto b = blocks_of("E2\nG160 R1 F30\nG00 X5");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[2].kind, MotionKind::kRapid);
}

}  // namespace
}  // namespace edm::hmi::test
