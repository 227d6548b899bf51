// check_program: the validation both the HMI and the runtime run on a whole part program.
#include "edm/machining/program_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace edm::machining {
namespace {

MachineTables tables() {
  MachineTables t;
  t.conditions.push_back({.e = 1, .name = "drill", .wear_ratio = 0.6});
  t.conditions.push_back({.e = 2, .name = "finish", .polarity = Polarity::kPositive});
  t.axes.push_back({.name = 'X', .min_mm = -10, .max_mm = 10});
  t.axes.push_back({.name = 'Y', .min_mm = -10, .max_mm = 10});
  t.axes.push_back({.name = 'Z', .min_mm = -60, .max_mm = 5});
  return t;
}

MotionBlock at(MotionKind k, double x, double y, double z, int line) {
  MotionBlock b;
  b.kind = k;
  b.target = {x, y, z};
  b.line = line;
  b.col = 1;
  return b;
}

std::vector<ProgramIssue> check(const std::vector<MotionBlock>& p) {
  return check_program(p, tables(), Vec3{0, 0, 1});
}

TEST(ProgramCheck, AGoodDrillThenFinishProgramPasses) {
  std::vector<MotionBlock> p;
  p.push_back(at(MotionKind::kRapid, 1, 1, 1, 1));
  MotionBlock e1;
  e1.kind = MotionKind::kCondition;
  e1.condition = 1;
  p.push_back(e1);
  MotionBlock d = at(MotionKind::kDrill, 1, 1, -20, 3);
  d.condition = 1;
  d.z_travel_mm = 21 * 1.6;
  p.push_back(d);
  MotionBlock o;
  o.kind = MotionKind::kOrbitFinish;
  o.condition = 2;
  o.final_radius_mm = 0.6;
  p.push_back(o);
  p.push_back(at(MotionKind::kRapid, 1, 1, 1, 5));
  p.push_back(at(MotionKind::kEnd, 0, 0, 0, 6));
  EXPECT_TRUE(check(p).empty()) << check(p)[0].message;
}

TEST(ProgramCheck, SoftLimitsNameTheLine) {
  const auto issues = check({at(MotionKind::kRapid, 11, 0, 0, 7)});
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].line, 7);
  EXPECT_TRUE(issues[0].soft_limit);
  EXPECT_EQ(issues[0].axis, 'X');  // an end point: a G-code reader points at the X word
  EXPECT_EQ(issues[0].message, "X 11.000 mm is beyond the X soft limit (-10.000..10.000 mm)");
}

TEST(ProgramCheck, ArcExtremesAreCheckedNotOnlyTheEndPoints) {
  // A half circle from (0,5) to (0,-5) about the origin, CCW: passes through (−5, 0) — inside.
  MotionBlock a = at(MotionKind::kArcCcw, 0, -5, 0, 2);
  a.centre = {0, 0, 0};
  std::vector<MotionBlock> p{at(MotionKind::kRapid, 0, 5, 0, 1), a};
  EXPECT_TRUE(check(p).empty());
  // Radius 12 about (−√119, 0), from (0, 5) to (0, −5): clockwise it is the short arc through
  // (12 − √119, 0) ≈ (1.09, 0), inside; counter-clockwise the long way round through (.., ±12)
  // and (−22.9, 0), outside the ±10 limits although both end points are inside.
  MotionBlock b = at(MotionKind::kArcCw, 0, -5, 0, 2);
  b.centre = {-std::sqrt(144.0 - 25.0), 0, 0};
  EXPECT_TRUE(check({at(MotionKind::kRapid, 0, 5, 0, 1), b}).empty());
  b.kind = MotionKind::kArcCcw;
  const auto issues = check({at(MotionKind::kRapid, 0, 5, 0, 1), b});
  // Each axis's extreme once: X −22.9 (min), Y −12 (min), Y +12 (max).
  ASSERT_EQ(issues.size(), 3u);
  EXPECT_EQ(issues[0].line, 2);
  EXPECT_TRUE(issues[0].soft_limit);
  EXPECT_EQ(issues[0].axis, 0);  // an extent: named at the motion word
  EXPECT_EQ(issues[0].message.rfind("G03 arc: X -22.909 mm is beyond the X soft limit", 0), 0u)
      << issues[0].message;
}

TEST(ProgramCheck, InconsistentArcAndZeroRadius) {
  MotionBlock a = at(MotionKind::kArcCw, 3, 0, 0, 2);
  a.centre = {0, 0, 0};
  auto issues = check({at(MotionKind::kRapid, 0, 2, 0, 1), a});  // r 2 vs 3
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_NE(issues[0].message.find("differ"), std::string::npos);
  MotionBlock z = at(MotionKind::kArcCw, 0, 0, 0, 2);
  z.centre = {0, 0, 0};
  issues = check({at(MotionKind::kRapid, 0, 0, 0, 1), z});
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_NE(issues[0].message.find("zero radius"), std::string::npos);
}

TEST(ProgramCheck, BadBlocksAreEachRefused) {
  MotionBlock unknown_e;
  unknown_e.kind = MotionKind::kCondition;
  unknown_e.condition = 9;
  MotionBlock up_drill = at(MotionKind::kDrill, 0, 0, 2, 1);
  up_drill.condition = 1;
  up_drill.z_travel_mm = 1;
  MotionBlock no_travel = at(MotionKind::kDrill, 0, 0, -1, 1);
  no_travel.condition = 1;
  MotionBlock unarmed = at(MotionKind::kDrill, 0, 0, -1, 1);
  unarmed.z_travel_mm = 2;
  MotionBlock nan = at(MotionKind::kLinear, std::numeric_limits<double>::quiet_NaN(), 0, 0, 1);
  MotionBlock dwell;
  dwell.kind = MotionKind::kDwell;
  dwell.dwell_s = -1;
  MotionBlock orbit;
  orbit.kind = MotionKind::kOrbitFinish;
  orbit.condition = 2;
  for (const MotionBlock& b : {unknown_e, up_drill, no_travel, unarmed, nan, dwell, orbit}) {
    EXPECT_FALSE(check({b}).empty()) << to_string(b.kind);
  }
  EXPECT_FALSE(check({}).empty()) << "empty program";
  EXPECT_FALSE(
      check({at(MotionKind::kEnd, 0, 0, 0, 1), at(MotionKind::kRapid, 0, 0, 0, 2)}).empty())
      << "block after the end";
}

}  // namespace
}  // namespace edm::machining
