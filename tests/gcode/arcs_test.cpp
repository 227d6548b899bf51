// G02/G03: quarter, half and full circles, extra turns, direction, centre consistency, extent.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

using machining::Vec3;

// `b` is an arc of `kind` about `centre` that ends at `target`.
void expect_arc(const MotionBlock& b, MotionKind kind, const Vec3& centre, const Vec3& target) {
  EXPECT_EQ(b.kind, kind);
  EXPECT_EQ(b.centre, centre);
  EXPECT_EQ(b.target, target);
}

TEST(GcodeArcs, QuarterCircleCounterClockwise) {
  const auto b = blocks_of("G00 X10 Y0\nG03 X0 Y10 I-10 J0 F60");
  ASSERT_EQ(b.size(), 2u);
  expect_arc(b[1], MotionKind::kArcCcw, {0, 0, 0}, {0, 10, 0});
  EXPECT_EQ(b[1].turns, 0);
  EXPECT_DOUBLE_EQ(b[1].feed_mm_s, 1.0);
  EXPECT_EQ(b[1].line, 2);
  EXPECT_EQ(b[1].col, 1);
}

TEST(GcodeArcs, HalfCircleClockwiseAndDirectionKinds) {
  const auto b = blocks_of("G00 X-5 Y0\nG02 X5 Y0 I5 F60\nG03 X-5 Y0 I-5");
  ASSERT_EQ(b.size(), 3u);
  expect_arc(b[1], MotionKind::kArcCw, {0, 0, 0}, {5, 0, 0});
  expect_arc(b[2], MotionKind::kArcCcw, {0, 0, 0}, {-5, 0, 0});
}

TEST(GcodeArcs, CentreIsRelativeToTheStartEvenInAbsoluteMode) {
  const auto b = blocks_of("G90 G00 X20 Y30 Z1\nG02 X24 Y30 I2 J0 F60");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].centre, (Vec3{22, 30, 1}));
}

TEST(GcodeArcs, IncrementalEndPoint) {
  const auto b = blocks_of("G00 X20 Y30\nG91 G03 X-4 Y4 I-4 J0 F60");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].centre, (Vec3{16, 30, 0}));
  EXPECT_EQ(b[1].target, (Vec3{16, 34, 0}));
}

TEST(GcodeArcs, FullCircleWhenTheEndIsTheStart) {
  const auto b = blocks_of("G00 X10 Y10\nG02 I-3 F60\nG03 X10 Y10 J2");
  ASSERT_EQ(b.size(), 3u);
  expect_arc(b[1], MotionKind::kArcCw, {7, 10, 0}, {10, 10, 0});
  expect_arc(b[2], MotionKind::kArcCcw, {10, 12, 0}, {10, 10, 0});
}

TEST(GcodeArcs, PAddsWholeTurns) {
  const auto b = blocks_of("G00 X1\nG03 I-1 P3 F60\nG02 X-1 I-1 P1");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[1].turns, 3);
  EXPECT_EQ(b[2].turns, 1);
  EXPECT_EQ(b[2].target, (Vec3{-1, 0, 0}));
  EXPECT_EQ(first_error("G03 I-1 P1.5 F60"),
            "t.nc:1:9: extra turns 'P1.5' must be a whole number 0..1000");
  EXPECT_EQ(first_error("G03 I-1 P-1 F60"),
            "t.nc:1:9: extra turns 'P-1' must be a whole number 0..1000");
  EXPECT_EQ(first_error("G03 I-1 P1001 F60"),
            "t.nc:1:9: extra turns 'P1001' must be a whole number 0..1000");
}

TEST(GcodeArcs, InconsistentCentreIsRefused) {
  EXPECT_EQ(first_error("G02 X10 Y0 I4 J0 F60"),
            "t.nc:1:1: G02 end point is not on the arc's circle: start radius 4.000 mm, end radius "
            "6.000 mm (tolerance 0.002 mm)");
}

TEST(GcodeArcs, ToleranceIsAbsoluteForSmallAndRelativeForLargeRadii) {
  // R = 5: 0.002 mm.
  EXPECT_TRUE(interpret("G02 X10.0019 I5 F60\nM30").ok());
  EXPECT_FALSE(interpret("G02 X10.0021 I5 F60\nM30").ok());
  // R = 50: 1e-4·R = 0.005 mm.
  EXPECT_TRUE(interpret("G00 X-50\nG02 X50.0049 I50 F60\nM30").ok());
  EXPECT_FALSE(interpret("G00 X-50\nG02 X50.0051 I50 F60\nM30").ok());
  GcodeOptions o;
  o.arc_tolerance_mm = 0.01;
  EXPECT_TRUE(interpret("G02 X10.009 I5 F60\nM30", o).ok());
}

TEST(GcodeArcs, ZeroRadiusMissingCentreAndHelixAreRefused) {
  EXPECT_EQ(first_error("G02 X0 I0 J0 F60"),
            "t.nc:1:1: G02 arc radius is zero (I and J put the centre on the start)");
  EXPECT_EQ(first_error("G02 X10 F60"),
            "t.nc:1:1: G02 needs I and/or J (the centre, relative to the start point)");
  EXPECT_EQ(first_error("G03"),
            "t.nc:1:1: G03 needs I and/or J (the centre, relative to the start point)");
  EXPECT_EQ(first_error("G03 I1 F60\nX2"),
            "t.nc:2:1: G03 needs I and/or J (the centre, relative to the start point)");
  EXPECT_EQ(first_error("G02 X2 Z-1 I1 F60"),
            "t.nc:1:8: helical arcs are not supported: Z must not change in a G02 block");
}

TEST(GcodeArcs, SoftLimitsCoverTheSweptExtentNotOnlyTheEnds) {
  // Centre (95, 0), radius √41 ≈ 6.403: the end points have X = 99 but the counter-clockwise
  // arc passes through angle 0, at X ≈ 101.403, beyond +100.
  EXPECT_EQ(first_error("G00 X99 Y-5\nG03 X99 Y5 I-4 J5 F60"),
            "t.nc:2:1: G03 arc: X 101.403 mm is beyond the X soft limit (-100.000..100.000 mm)");
  // The clockwise arc between the same points goes the other way round (X ≥ 88.6): fine.
  EXPECT_TRUE(interpret("G00 X99 Y-5\nG02 X99 Y5 I-4 J5 F60\nM30").ok());
  // A full circle reaches all four extremes.
  EXPECT_EQ(first_error("G00 X0 Y90\nG02 I0 J6 F60"),
            "t.nc:2:1: G02 arc: Y 102.000 mm is beyond the Y soft limit (-100.000..100.000 mm)");
  EXPECT_TRUE(interpret("G00 X0 Y90\nG02 I0 J5 F60\nM30").ok());
}

}  // namespace
}  // namespace edm::hmi::test
