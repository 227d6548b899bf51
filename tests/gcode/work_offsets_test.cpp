// Work offsets in the interpreter (docs/gcode.md "Work offsets"): G54..G59 select one of the
// machine's frames, G92 shifts the program's coordinates so the current point reads the given
// value, G92.1 clears it; blocks come out in machine coordinates; the work surface for drilling
// depths and the wear pre-compensation is the frame's Z0; soft limits stay in machine coordinates.
#include <gtest/gtest.h>

#include <string>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

using machining::Vec3;

/// G54 at (10, -5, -20), G55 at (-30, 40, -35), G59 at (1, 2, 3); the others zero.
WorkOffsets sample_offsets() {
  WorkOffsets o;
  o.frame[0] = {10.0, -5.0, -20.0};
  o.frame[1] = {-30.0, 40.0, -35.0};
  o.frame[5] = {1.0, 2.0, 3.0};
  return o;
}

GcodeOptions with_offsets(Vec3 start = {}) {
  GcodeOptions o;
  o.offsets = sample_offsets();
  o.start_mm = start;
  return o;
}

TEST(GcodeWorkOffsets, G54IsActiveAtTheStartAndBlocksAreInMachineCoordinates) {
  const auto b = blocks_of("G00 X1 Y2 Z3", with_offsets());
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].target, (Vec3{11.0, -3.0, -17.0}));  // work + G54
}

TEST(GcodeWorkOffsets, EachFrameShiftsByItsOffset) {
  const auto b =
      blocks_of("G55 G00 X1 Y2 Z3\nG59 X1 Y2 Z3\nG56 X1 Y2 Z3\nG54 X1 Y2 Z3", with_offsets());
  ASSERT_EQ(b.size(), 4u);
  EXPECT_EQ(b[0].target, (Vec3{-29.0, 42.0, -32.0}));
  EXPECT_EQ(b[1].target, (Vec3{2.0, 4.0, 6.0}));
  EXPECT_EQ(b[2].target, (Vec3{1.0, 2.0, 3.0}));  // G56 is zero here
  EXPECT_EQ(b[3].target, (Vec3{11.0, -3.0, -17.0}));
}

TEST(GcodeWorkOffsets, TheFrameIsModalAndAxesNotNamedStayWhereTheyAre) {
  // From machine (0, 0, 0): G55 X1 moves X only; Y and Z keep their machine values.
  const auto b = blocks_of("G55\nG00 X1\nY0", with_offsets());
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].target, (Vec3{-29.0, 0.0, 0.0}));
  EXPECT_EQ(b[1].target, (Vec3{-29.0, 40.0, 0.0}));
}

TEST(GcodeWorkOffsets, IncrementalMovesAndArcCentresAreDistancesTheSameInEveryFrame) {
  const auto b = blocks_of("G00 X0 Y0 Z1\nG91 X5\nG90 G02 X15 Y0 I5 J0 F60", with_offsets());
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[1].target, (Vec3{15.0, -5.0, -19.0}));
  EXPECT_EQ(b[2].target, (Vec3{25.0, -5.0, -19.0}));
  EXPECT_EQ(b[2].centre, (Vec3{20.0, -5.0, -19.0}));  // start (15, -5) + (5, 0)
}

TEST(GcodeWorkOffsets, EachBlockRemembersItsFrame) {
  const GcodeResult r = interpret("G00 X0\nG55 X0\nG92 X7\nM30", with_offsets());
  ASSERT_TRUE(r.ok()) << joined(r);
  ASSERT_EQ(r.frames.size(), r.blocks.size());
  EXPECT_EQ(r.frames[0].frame, 0);
  EXPECT_EQ(r.frames[0].offset_mm, (Vec3{10.0, -5.0, -20.0}));
  EXPECT_FALSE(r.frames[0].g92);
  EXPECT_EQ(r.frames[1].frame, 1);
  EXPECT_EQ(r.frames[1].offset_mm, (Vec3{-30.0, 40.0, -35.0}));
  // G92 X7 at machine X −30: the X offset grows by −7 (the end block is after it).
  EXPECT_EQ(r.frames[2].offset_mm, (Vec3{-37.0, 40.0, -35.0}));
  EXPECT_TRUE(r.frames[2].g92);
  EXPECT_EQ(r.start_mm, (Vec3{}));
}

TEST(GcodeG92, TheCurrentPointReadsTheGivenValue) {
  // At work (1, 2, 3) in G54, G92 X0 Y0 makes that point X0 Y0; Z keeps its offset.
  const auto b = blocks_of("G00 X1 Y2 Z3\nG92 X0 Y0\nG00 X5 Y0 Z3", with_offsets());
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].target, (Vec3{16.0, -3.0, -17.0}));
}

TEST(GcodeG92, IsAbsoluteUnderG91AndClearedByG92Point1) {
  const auto b =
      blocks_of("G00 X1 Y1 Z1\nG91 G92 X10\nG90 G00 X10\nG92.1\nG00 X10", with_offsets());
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[1].target.x, 11.0);  // X10 is the point G92 named: unchanged machine X 11
  EXPECT_EQ(b[2].target.x, 20.0);  // cleared: X10 of G54
}

TEST(GcodeG92, AppliesInEveryFrameAndIsNotRetainedBetweenPrograms) {
  const auto b = blocks_of("G00 X0\nG92 X-2\nG55 G00 X0", with_offsets());
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].target.x, -30.0 + 2.0);
  // A new program starts without it.
  EXPECT_EQ(blocks_of("G00 X0", with_offsets())[0].target.x, 10.0);
}

TEST(GcodeWorkOffsets, DrillDepthAndWearAreMeasuredFromTheFramesZ0) {
  // G54's Z0 is machine −20: the surface. From work Z0.5 to Z−8: 8 mm eroded.
  const GcodeResult r = interpret("G00 X0 Y0 Z0.5\nE1\nG01 Z-8 F60\nM30", with_offsets({0, 0, 10}));
  ASSERT_TRUE(r.ok()) << joined(r);
  const auto d = of_kind(r.blocks, MotionKind::kDrill);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].target, (Vec3{10.0, -5.0, -28.0}));
  EXPECT_DOUBLE_EQ(d[0].depth_mm, 8.0);
  EXPECT_DOUBLE_EQ(d[0].depth_done_mm, 0.0);
  EXPECT_NEAR(d[0].z_travel_mm, 8.5 + 0.6 * 1.25 * 8.0, 1e-9);  // eq. 10 on the 8 mm only
  EXPECT_NEAR(r.drill_depth_mm, 8.0, 1e-9);
}

TEST(GcodeWorkOffsets, G92MovesTheSurfaceToo) {
  // The operator declares the current point Z1 (the electrode 1 mm above the surface).
  const auto d = of_kind(blocks_of("G00 X0 Y0 Z5\nG92 Z1\nE1\nG01 Z-4 F60", with_offsets()),
                         MotionKind::kDrill);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_DOUBLE_EQ(d[0].depth_mm, 4.0);
  EXPECT_DOUBLE_EQ(d[0].target.z, -15.0 - 5.0);  // machine −15 (work Z5) less 5 mm
  EXPECT_NEAR(d[0].z_travel_mm, 5.0 + 0.6 * 1.25 * 4.0, 1e-9);
}

TEST(GcodeWorkOffsets, ZeroOffsetsKeepTheOldMachineCoordinateProgramsAsTheyWere) {
  const auto d = of_kind(blocks_of("G00 Z0.5\nE1\nG01 Z-20 F60"), MotionKind::kDrill);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_DOUBLE_EQ(d[0].depth_mm, 20.0);
  EXPECT_DOUBLE_EQ(d[0].target.z, -20.0);
  EXPECT_NEAR(d[0].z_travel_mm, 20.5 + 0.6 * 1.25 * 20.0, 1e-9);
}

TEST(GcodeWorkOffsets, ADrillingBlockMustEndBelowTheWorkSurface) {
  GcodeOptions o = with_offsets();
  const GcodeResult r = interpret("G00 X0 Y0 Z5\nE1\nG01 Z1 F60\nM30", o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.messages().front(),
            "t.nc:3:5: a drilling block must end below the work surface (Z0 of G54): it ends at "
            "Z 1.000");
}

TEST(GcodeWorkOffsets, SoftLimitsStayInMachineCoordinatesAndNameTheLine) {
  // Work X95 is inside ±100, but G54's X offset 10 puts it at machine X 105.
  const GcodeResult r = interpret("G00 Z5\nG00 X95\nM30", with_offsets());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.messages().front(),
            "t.nc:2:5: X 105.000 mm is beyond the X soft limit (-100.000..100.000 mm)");
  // Work Z−45 is machine −65 in G54: beyond −60. The same program in G56 (zero) is fine.
  EXPECT_EQ(interpret("G00 Z-45\nM30", with_offsets()).messages().front(),
            "t.nc:1:5: Z -65.000 mm is beyond the Z soft limit (-60.000..20.000 mm)");
  EXPECT_TRUE(interpret("G56\nG00 Z-45\nM30", with_offsets()).ok());
  // The wear pre-compensated travel too: from work Z0 (machine −20) down 25 mm + 18.75 of wear.
  EXPECT_EQ(interpret("G00 Z0\nE1\nG01 Z-25 F60\nM30", with_offsets()).messages().front(),
            "t.nc:3:5: drilling with wear pre-compensation moves Z to -63.750 mm (nominal "
            "-45.000 - wear 18.750 mm), beyond the Z soft limit (-60.000..20.000 mm)");
}

TEST(GcodeWorkOffsets, ConflictingAndUnsupportedWordsAreErrorsAtTheirColumn) {
  EXPECT_EQ(first_error("G54 G92 X0"),
            "t.nc:1:5: 'G92' conflicts with 'G54' in the same block: select the work frame and "
            "set or clear the G92 offset in separate blocks");
  EXPECT_EQ(first_error("G92.1 G55"),
            "t.nc:1:7: 'G55' conflicts with 'G92.1' in the same block: select the work frame and "
            "set or clear the G92 offset in separate blocks");
  EXPECT_EQ(first_error("G54 G55"),
            "t.nc:1:5: 'G55' conflicts with 'G54' in the same block: both are work-frame codes "
            "(modal group 12: G54..G59)");
  EXPECT_EQ(first_error("G59.1"),
            "t.nc:1:1: 'G59.1' is not supported: the work frames are G54..G59");
  EXPECT_EQ(first_error("G53 G00 X0"),
            "t.nc:1:1: 'G53' (a move in machine coordinates) is not supported: select a work "
            "frame G54..G59 whose offset is zero instead");
  EXPECT_EQ(first_error("G92"),
            "t.nc:1:1: G92 needs X, Y and/or Z (the coordinates the current point is to have)");
  EXPECT_EQ(first_error("G00 G92 X1"), "t.nc:1:1: 'G00' cannot share a block with 'G92'");
  EXPECT_EQ(first_error("G92 X1 I2"), "t.nc:1:8: 'I2' cannot share a block with 'G92'");
  EXPECT_EQ(first_error("G92.1 X1"), "t.nc:1:7: 'X1' cannot share a block with 'G92.1'");
  EXPECT_EQ(first_error("G04 P1 G92 X0"),
            "t.nc:1:8: 'G92' conflicts with 'G04' in the same block: both are non-modal codes "
            "(group 0: G04 G160 G92 G92.1)");
  EXPECT_EQ(first_error("G92.2 X0"),
            "t.nc:1:1: 'G92.2' is not supported: G92 offsets are not retained; G92.1 clears them");
}

TEST(GcodeWorkOffsets, ARefusedFrameOrOffsetBlockChangesNothing) {
  // The refused line does not switch to G55 (the next move is still in G54).
  const GcodeResult r = interpret("G55 G56\nG00 X0\nM30", with_offsets());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors.size(), 1u) << joined(r);
}

}  // namespace
}  // namespace edm::hmi::test
