// Per word and per modal group: what each word does and what is refused (docs/gcode.md).
#include <gtest/gtest.h>

#include <string>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

using machining::Vec3;

TEST(GcodeProgram, EmptyProgramHasNoEnd) {
  const GcodeResult r = interpret("");
  ASSERT_EQ(r.messages().size(), 1u);
  EXPECT_EQ(r.messages()[0], "t.nc:1:1: program has no end: finish it with M02 or M30");
}

TEST(GcodeProgram, EndOnlyGivesOneEndBlock) {
  for (const char* end : {"M30", "M02", "M2", "m30"}) {
    const GcodeResult r = interpret(end);
    ASSERT_TRUE(r.ok()) << joined(r);
    ASSERT_EQ(r.blocks.size(), 1u);
    EXPECT_EQ(r.blocks[0].kind, MotionKind::kEnd);
    EXPECT_EQ(r.blocks[0].line, 1);
    EXPECT_EQ(r.blocks[0].col, 1);
  }
}

TEST(GcodeProgram, NothingButCommentsAndPercentAfterTheEnd) {
  EXPECT_TRUE(interpret("G00 X1\nM30\n(done)\n; really\n\n%\n").ok());
  EXPECT_EQ(first_error("M02\nG00 X1"),
            "t.nc:2:1: nothing may follow the program end (M02 on line 1)");
}

TEST(GcodeProgram, PercentDelimitersAndTextAfterTheClosingOne) {
  const GcodeResult r = interpret("%\nG00 X1\nM30\n%\nthis is ignored ### G20\n");
  ASSERT_TRUE(r.ok()) << joined(r);
  EXPECT_EQ(r.blocks.size(), 2u);
  EXPECT_EQ(first_error("%G00 X1"), "t.nc:1:2: '%' must be alone on its line (program delimiter)");
  EXPECT_EQ(first_error("G00 X1 %"), "t.nc:1:8: '%' must be alone on its line (program delimiter)");
}

TEST(GcodeComments, ParenthesesAndSemicolonAreSkipped) {
  const auto b = blocks_of("(start) G00 X1 (mid) Y2 ; trailing G20 words are a comment");
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].kind, MotionKind::kRapid);
  EXPECT_EQ(b[0].target, (Vec3{1, 2, 0}));
  EXPECT_EQ(b[0].col, 9);  // the G00 word
}

TEST(GcodeComments, MalformedCommentsAreRefused) {
  EXPECT_EQ(first_error("G00 X1 (open"),
            "t.nc:1:8: unclosed comment: '(' without ')' on the same line");
  EXPECT_EQ(first_error("G00 (a (b) c) X1"),
            "t.nc:1:8: '(' inside a comment (comments do not nest)");
  EXPECT_EQ(first_error("G00 X1 )"), "t.nc:1:8: ')' without '('");
}

TEST(GcodeLexer, LowerCaseLeadingZerosBlanksAndNumberForms) {
  const auto b = blocks_of("g0 x.5 y-.25 z+2\nG000 X 5. Y-0\nG00X1Y2Z3");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[0].target, (Vec3{0.5, -0.25, 2.0}));
  EXPECT_EQ(b[1].target, (Vec3{5.0, 0.0, 2.0}));
  EXPECT_EQ(b[2].target, (Vec3{1.0, 2.0, 3.0}));
}

TEST(GcodeLexer, MalformedNumbersAndStrayCharacters) {
  EXPECT_EQ(first_error("G00 X1.2.3"), "t.nc:1:5: malformed number in 'X1.2.3'");
  EXPECT_EQ(first_error("G00 X--1"), "t.nc:1:5: malformed number in 'X--1'");
  EXPECT_EQ(first_error("G00 X."), "t.nc:1:5: malformed number in 'X.'");
  EXPECT_EQ(first_error("G00 X Y1"), "t.nc:1:5: missing number after 'X'");
  EXPECT_EQ(first_error("G00 X1 #"), "t.nc:1:8: unexpected character '#'");
  EXPECT_EQ(first_error("G00 X1 \x01"), "t.nc:1:8: unexpected character 0x01");
  EXPECT_EQ(first_error("G00 12"), "t.nc:1:5: number '12' without a letter");
  EXPECT_EQ(first_error("G00 X1234567890123456789012345"),
            "t.nc:1:5: number too long in 'X123456789012345678901234'...");
}

TEST(GcodeLexer, CrLfLineEndsAreAccepted) {
  const GcodeResult r = interpret("G00 X1\r\nM30\r\n");
  ASSERT_TRUE(r.ok()) << joined(r);
  EXPECT_EQ(r.blocks.size(), 2u);
}

TEST(GcodeLexer, OverlongLinesAreRefused) {
  GcodeOptions o;
  o.max_line_length = 40;
  const GcodeResult r = interpret("G00 X1 (" + std::string(60, 'a') + ")\nM30\n", o);
  ASSERT_EQ(r.messages().size(), 1u);
  EXPECT_EQ(r.messages()[0], "t.nc:1:41: line longer than 40 characters");
  EXPECT_EQ(first_error(std::string(1100, ' ') + "G00"),
            "t.nc:1:1025: line longer than 1024 characters");
}

TEST(GcodeWords, NMustComeFirstAndBeWhole) {
  const auto b = blocks_of("N10 G00 X1");
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].col, 5);
  EXPECT_EQ(first_error("G00 N10 X1"),
            "t.nc:1:5: 'N' (block number) must be the first word of the block");
  EXPECT_EQ(first_error("N1.5 G00 X1"),
            "t.nc:1:1: block number 'N1.5' must be a whole number >= 0");
}

TEST(GcodeWords, UnknownLettersAndCodes) {
  EXPECT_EQ(first_error("S100"), "t.nc:1:1: unknown word 'S100': this dialect has no 'S' words");
  EXPECT_EQ(first_error("G00 T1"), "t.nc:1:5: unknown word 'T1': this dialect has no 'T' words");
  EXPECT_EQ(first_error("G02 X1 K2"),
            "t.nc:1:8: unknown word 'K2': arcs are in the XY plane only (G17), their centre is "
            "given by I and J");
  EXPECT_EQ(first_error("G05 X1"), "t.nc:1:1: unknown G code 'G05'");
  EXPECT_EQ(first_error("G1.5 X1"), "t.nc:1:1: unknown G code 'G1.5'");
  EXPECT_EQ(first_error("M06"), "t.nc:1:1: unknown M code 'M06'");
}

TEST(GcodeWords, AWordTwiceInOneBlock) {
  EXPECT_EQ(first_error("G00 X1 X2"), "t.nc:1:8: 'X' given twice in one block (first at column 5)");
  EXPECT_EQ(first_error("G01 X1 F10 F20"),
            "t.nc:1:12: 'F' given twice in one block (first at column 8)");
}

TEST(GcodeModalGroups, OneWordPerGroupPerBlock) {
  EXPECT_EQ(first_error("G00 G01 X1"),
            "t.nc:1:5: 'G01' conflicts with 'G00' in the same block: both are motion codes "
            "(modal group 1: G00 G01 G02 G03)");
  EXPECT_EQ(first_error("G90 G91"),
            "t.nc:1:5: 'G91' conflicts with 'G90' in the same block: both are distance-mode codes "
            "(modal group 3: G90 G91)");
  EXPECT_EQ(first_error("G17 G17"),
            "t.nc:1:5: 'G17' conflicts with 'G17' in the same block: both are plane codes (modal "
            "group 2)");
  EXPECT_EQ(first_error("G21 G21"),
            "t.nc:1:5: 'G21' conflicts with 'G21' in the same block: both are unit codes (modal "
            "group 6: G20 G21)");
  EXPECT_EQ(first_error("G04 P1 G160 R1"),
            "t.nc:1:8: 'G160' conflicts with 'G04' in the same block: both are non-modal codes "
            "(group 0: G04 G160 G92 G92.1)");
  EXPECT_EQ(first_error("M03 M05"),
            "t.nc:1:5: 'M05' conflicts with 'M03' in the same block: both are rotation codes "
            "(modal group 7: M03 M05)");
  EXPECT_EQ(first_error("M08 M09"),
            "t.nc:1:5: 'M09' conflicts with 'M08' in the same block: both are flushing codes "
            "(modal group 8: M08 M09)");
  EXPECT_EQ(first_error("M02 M30"),
            "t.nc:1:5: 'M30' conflicts with 'M02' in the same block: both are stop and end codes "
            "(modal group 4: M00 M01 M02 M30)");
}

TEST(GcodeModalGroups, DifferentGroupsShareABlock) {
  const auto b = blocks_of("G17 G21 G91 G01 X1 F60 M03 M08");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[0].kind, MotionKind::kRotation);
  EXPECT_EQ(b[1].kind, MotionKind::kFlushing);
  EXPECT_EQ(b[2].kind, MotionKind::kLinear);
}

TEST(GcodePlaneAndUnits, OnlyXyAndBothUnits) {
  EXPECT_TRUE(interpret("G17\nG21\nM30").ok());
  EXPECT_TRUE(interpret("G17\nG20\nM30").ok()) << "inches: tests/gcode/units_test.cpp";
  EXPECT_EQ(first_error("G18"),
            "t.nc:1:1: 'G18' is not supported: arcs are in the XY plane only (G17)");
  EXPECT_EQ(first_error("G19"),
            "t.nc:1:1: 'G19' is not supported: arcs are in the XY plane only (G17)");
}

TEST(GcodeDistanceMode, AbsoluteAndIncremental) {
  const auto c = blocks_of("G00 X10 Y10 Z5\nG91 X1 Y-2\nX1 Z-1\nG90 X3\nY4");
  ASSERT_EQ(c.size(), 5u);
  EXPECT_EQ(c[0].target, (Vec3{10, 10, 5}));
  EXPECT_EQ(c[1].target, (Vec3{11, 8, 5}));
  EXPECT_EQ(c[2].target, (Vec3{12, 8, 4}));
  EXPECT_EQ(c[3].target, (Vec3{3, 8, 4}));
  EXPECT_EQ(c[4].target, (Vec3{3, 4, 4}));
}

TEST(GcodeDistanceMode, StartPointOptionIsTheFirstReference) {
  GcodeOptions o;
  o.start_mm = {5, 6, 7};
  const auto b = blocks_of("G91 G00 X1", o);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].target, (Vec3{6, 6, 7}));
}

TEST(GcodeMotion, RapidAndLinearAreModal) {
  const auto b = blocks_of("G00 X1\nY2\nG01 X3 F120\nY4\nG00\nZ5");
  ASSERT_EQ(b.size(), 5u);
  EXPECT_EQ(b[0].kind, MotionKind::kRapid);
  EXPECT_EQ(b[1].kind, MotionKind::kRapid);
  EXPECT_EQ(b[1].col, 1);  // no G word: the first axis word
  EXPECT_EQ(b[2].kind, MotionKind::kLinear);
  EXPECT_DOUBLE_EQ(b[2].feed_mm_s, 2.0);  // 120 mm/min
  EXPECT_EQ(b[3].kind, MotionKind::kLinear);
  EXPECT_EQ(b[3].target, (Vec3{3, 4, 0}));
  EXPECT_EQ(b[4].kind, MotionKind::kRapid);
  EXPECT_EQ(b[4].feed_mm_s, 0.0);
  EXPECT_EQ(b[4].line, 6);
}

TEST(GcodeMotion, AxisWordsNeedAMotionMode) {
  EXPECT_EQ(first_error("X1"),
            "t.nc:1:1: 'X1' without a motion mode: program G00, G01, G02 or G03 first");
}

TEST(GcodeFeed, RequiredBeforeTheFirstFeedMoveAndPositive) {
  const std::vector<std::string> e = errors_of("G01 X1\nX2\nX3");
  ASSERT_EQ(e.size(), 1u);  // reported once
  EXPECT_EQ(e[0], "t.nc:1:1: G01 needs a feed rate: program F (mm/min) before the first feed move");
  EXPECT_EQ(first_error("G01 X1 F0"), "t.nc:1:8: feed rate 'F0' must be > 0 (mm/min)");
  EXPECT_EQ(first_error("F-5"), "t.nc:1:1: feed rate 'F-5' must be > 0 (mm/min)");
  GcodeOptions o;
  o.default_feed_mm_min = 30.0;
  const auto b = blocks_of("G01 X1\nF90\nX2", o);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_DOUBLE_EQ(b[0].feed_mm_s, 0.5);
  EXPECT_DOUBLE_EQ(b[1].feed_mm_s, 1.5);
}

TEST(GcodeCondition, SelectArmAndDisarm) {
  const auto b = blocks_of("E2\nG00 X1\nE0\nG00 X2");
  ASSERT_EQ(b.size(), 4u);
  EXPECT_EQ(b[0].kind, MotionKind::kCondition);
  EXPECT_EQ(b[0].condition, 2);
  EXPECT_EQ(b[1].condition, 2);  // the active E travels with every block
  EXPECT_EQ(b[2].kind, MotionKind::kCondition);
  EXPECT_EQ(b[2].condition, 0);
  EXPECT_EQ(b[3].condition, 0);
  EXPECT_EQ(first_error("E7"), "t.nc:1:1: unknown condition 'E7' (this machine has E1 E2)");
  EXPECT_EQ(first_error("E1.5"),
            "t.nc:1:1: condition 'E1.5' must be a whole number >= 0 (E0 disarms)");
  EXPECT_EQ(first_error("E-1"),
            "t.nc:1:1: condition 'E-1' must be a whole number >= 0 (E0 disarms)");
  machining::MachineTables none;
  const GcodeResult r = interpret_gcode("E1\nM30", "n.nc", none);
  ASSERT_EQ(r.messages().size(), 1u);
  EXPECT_EQ(r.messages()[0], "n.nc:1:1: unknown condition 'E1' (this machine has no conditions)");
}

TEST(GcodeCondition, RunsBeforeTheMotionOfItsBlock) {
  const auto b = blocks_of("G00 Z1\nG01 Z-5 F60 E1");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[1].kind, MotionKind::kCondition);
  EXPECT_EQ(b[1].col, 13);
  EXPECT_EQ(b[2].kind, MotionKind::kDrill);
}

TEST(GcodeRotationFlushing, OnAndOff) {
  const auto b = blocks_of("M03\nM05\nM08\nM09\nM3 M9");
  ASSERT_EQ(b.size(), 6u);
  EXPECT_EQ(b[0].kind, MotionKind::kRotation);
  EXPECT_TRUE(b[0].on);
  EXPECT_FALSE(b[1].on);
  EXPECT_EQ(b[2].kind, MotionKind::kFlushing);
  EXPECT_TRUE(b[2].on);
  EXPECT_FALSE(b[3].on);
  EXPECT_EQ(b[4].kind, MotionKind::kRotation);
  EXPECT_EQ(b[5].kind, MotionKind::kFlushing);
  EXPECT_EQ(b[5].col, 4);
}

TEST(GcodeDwell, SecondsFromP) {
  const auto b = blocks_of("G04 P1.5\nG4 P0");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].kind, MotionKind::kDwell);
  EXPECT_DOUBLE_EQ(b[0].dwell_s, 1.5);
  EXPECT_DOUBLE_EQ(b[1].dwell_s, 0.0);
  EXPECT_EQ(first_error("G04"), "t.nc:1:1: G04 needs P (the dwell time in seconds)");
  EXPECT_EQ(first_error("G04 P-1"), "t.nc:1:5: dwell 'P-1' must be >= 0 seconds");
  EXPECT_EQ(first_error("G04 P1 X2"), "t.nc:1:8: 'X2' cannot share a block with 'G04'");
  EXPECT_EQ(first_error("G01 G04 P1"), "t.nc:1:1: 'G01' cannot share a block with 'G04'");
}

TEST(GcodeWords, UnusedPIAndRAreRefused) {
  EXPECT_EQ(first_error("G00 X1 P2"),
            "t.nc:1:8: 'P2' is only used by G04 (dwell) and G02/G03 (extra turns)");
  EXPECT_EQ(first_error("G01 X1 I2 F10"),
            "t.nc:1:8: 'I2' is only used by G02/G03 arcs (centre offset)");
  EXPECT_EQ(
      first_error("G00 X1 R2"),
      "t.nc:1:8: 'R2' is only used by the G160 orbit cycle (arcs take I and J, not a radius)");
}

TEST(GcodeErrors, AllCollectedInFileOrder) {
  const std::vector<std::string> e = errors_of("G00 X1 S1 X2\nG18\nG00 Y1\nM06");
  ASSERT_EQ(e.size(), 4u);
  EXPECT_EQ(e[0].substr(0, 11), "t.nc:1:8: u");
  EXPECT_EQ(e[1].substr(0, 11), "t.nc:1:11: ");
  EXPECT_EQ(e[2].substr(0, 9), "t.nc:2:1:");
  EXPECT_EQ(e[3].substr(0, 9), "t.nc:4:1:");
}

TEST(GcodeErrors, StopsAfterMaxErrors) {
  std::string text;
  for (int i = 0; i < 500; ++i) text += "S1\n";
  GcodeOptions o;
  o.max_errors = 10;
  const GcodeResult r = interpret(text, o);
  ASSERT_EQ(r.errors.size(), 11u);
  EXPECT_EQ(r.errors.back().message, "too many errors (10), stopping");
  EXPECT_EQ(r.errors[9].line, 10);
}

}  // namespace
}  // namespace edm::hmi::test
