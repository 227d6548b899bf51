// MDI (hmi/mdi.hpp): one line, the program's words and checks, from the machine's position in
// the active work frame; an end block appended.
#include "edm/hmi/mdi.hpp"

#include <gtest/gtest.h>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

using machining::Vec3;

WorkOffsets g54_at(Vec3 origin) {
  WorkOffsets o;
  o.frame[0] = origin;
  return o;
}

TEST(Mdi, StartsFromTheMachinePositionInTheActiveFrame) {
  // The machine is at (12, -3, -10); G54's origin is (10, -5, -20): work (2, 2, 10).
  const GcodeResult r =
      interpret_mdi("G91 G00 X1", test_tables(), g54_at({10, -5, -20}), {12.0, -3.0, -10.0});
  ASSERT_TRUE(r.ok()) << joined(r);
  ASSERT_EQ(r.blocks.size(), 2u);
  EXPECT_EQ(r.blocks[0].kind, MotionKind::kRapid);
  EXPECT_EQ(r.blocks[0].target, (Vec3{13.0, -3.0, -10.0}));
  EXPECT_EQ(r.blocks[1].kind, MotionKind::kEnd);  // appended
  EXPECT_EQ(r.blocks[1].line, 1);
  EXPECT_EQ(r.start_mm, (Vec3{12.0, -3.0, -10.0}));
  // Absolute words are work coordinates.
  const GcodeResult a =
      interpret_mdi("G00 X0 Y0", test_tables(), g54_at({10, -5, -20}), {12.0, -3.0, -10.0});
  ASSERT_TRUE(a.ok()) << joined(a);
  EXPECT_EQ(a.blocks[0].target, (Vec3{10.0, -5.0, -10.0}));
}

TEST(Mdi, DrillsFromTheFramesSurfaceWithTheProgramsWearPrecompensation) {
  const GcodeResult r =
      interpret_mdi("E1 G01 Z-2 F60", test_tables(), g54_at({0, 0, -20}), {0.0, 0.0, -19.5});
  ASSERT_TRUE(r.ok()) << joined(r);
  const auto d = of_kind(r.blocks, MotionKind::kDrill);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_DOUBLE_EQ(d[0].depth_mm, 2.0);
  EXPECT_NEAR(d[0].z_travel_mm, 2.5 + 0.6 * 1.25 * 2.0, 1e-9);
}

TEST(Mdi, HasTheProgramsChecks) {
  const WorkOffsets zero;
  const GcodeResult limit = interpret_mdi("G00 X150", test_tables(), zero, {});
  ASSERT_FALSE(limit.ok());
  EXPECT_EQ(limit.messages().front(),
            "MDI:1:5: X 150.000 mm is beyond the X soft limit (-100.000..100.000 mm)");
  EXPECT_EQ(interpret_mdi("G01 X1", test_tables(), zero, {}).messages().front(),
            "MDI:1:1: G01 needs a feed rate: program F (mm/min) before the first feed move");
  EXPECT_EQ(interpret_mdi("E7", test_tables(), zero, {}).messages().front(),
            "MDI:1:1: unknown condition 'E7' (this machine has E1 E2)");
  // Each line starts afresh: no motion mode from an earlier line.
  EXPECT_EQ(interpret_mdi("X1", test_tables(), zero, {}).messages().front(),
            "MDI:1:1: 'X1' without a motion mode: program G00, G01, G02 or G03 first");
}

TEST(Mdi, OneLineWithWordsAnEndIsAllowed) {
  const WorkOffsets zero;
  EXPECT_TRUE(interpret_mdi("G00 Z5 M30", test_tables(), zero, {}).ok());
  EXPECT_TRUE(interpret_mdi("G00 Z5\n", test_tables(), zero, {}).ok());  // a trailing newline
  EXPECT_EQ(interpret_mdi("G00 Z5\nG00 Z6", test_tables(), zero, {}).messages().front(),
            "MDI:1:7: MDI takes one line; this has several");
  EXPECT_EQ(interpret_mdi("  (just a comment)", test_tables(), zero, {}).messages().front(),
            "MDI:1:1: nothing to do: the line has no words");
  EXPECT_EQ(interpret_mdi("", test_tables(), zero, {}).messages().front(),
            "MDI:1:1: nothing to do: the line has no words");
}

}  // namespace
}  // namespace edm::hmi::test
