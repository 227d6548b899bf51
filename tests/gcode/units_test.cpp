// G20/G21 (issue 33 item 6): a program in inches gives the blocks of its millimetre twin, so the
// machine drills the same holes. Over seeded random programs (holes, arcs, an orbit, a G92, a
// dwell), the twin writes every inch value × 25.4 with 7 decimals: the end points, centres,
// depths, radii and feeds agree within 1 µm (and 1 µm/s); a dwell's P stays seconds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

constexpr double kMmPerInch = 25.4;

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.7f", v);
  return b;
}

struct Twins {
  std::string inch, mm;
  void line(const std::string& head, std::initializer_list<std::pair<char, double>> lengths,
            const std::string& tail = "") {
    std::string a = head, b = head;
    for (const auto& [letter, v] : lengths) {
      a += std::string(" ") + letter + num(v);
      b += std::string(" ") + letter + num(v * kMmPerInch);
    }
    inch += a + tail + "\n";
    mm += b + tail + "\n";
  }
};

// A random part: G20 (inch) against G21, same words otherwise.
Twins random_part(std::mt19937& rng) {
  std::uniform_real_distribution<double> xy(-3.0, 3.0);  // inches: within ±100 mm
  std::uniform_real_distribution<double> depth(0.02, 0.6);
  std::uniform_real_distribution<double> feed(2.0, 40.0);  // inch/min
  Twins t;
  t.inch = "G17 G20 G90 G54\n";
  t.mm = "G17 G21 G90 G54\n";
  t.line("G92", {{'X', 0.0}, {'Y', 0.0}, {'Z', 0.1}});
  for (int hole = 0; hole < 3; ++hole) {
    const double x = xy(rng), y = xy(rng);
    t.line("G00", {{'X', x}, {'Y', y}});
    t.line("G00", {{'Z', 0.02}});
    t.line("E1 M03 M08 G01", {{'Z', -depth(rng)}, {'F', feed(rng)}});
    t.line("G04 P0.5", {});
    if (hole == 1) t.line("E2 G160", {{'R', 0.03}, {'F', feed(rng)}});
    t.line("G00", {{'Z', 0.1}});
  }
  const double r = 0.5;
  t.line("E0 G01", {{'X', r}, {'Y', 0.0}, {'F', feed(rng)}});
  t.line("G02", {{'X', -r}, {'Y', 0.0}, {'I', -r}, {'J', 0.0}});
  t.line("G03", {{'X', r}, {'Y', 0.0}, {'I', r}, {'J', 0.0}});
  return t;
}

void expect_near(const machining::Vec3& a, const machining::Vec3& b, const char* what, int k) {
  EXPECT_NEAR(a.x, b.x, 1e-3) << what << " of block " << k;
  EXPECT_NEAR(a.y, b.y, 1e-3) << what << " of block " << k;
  EXPECT_NEAR(a.z, b.z, 1e-3) << what << " of block " << k;
}

class GcodeUnits : public ::testing::TestWithParam<unsigned> {};

TEST_P(GcodeUnits, AnInchProgramGivesTheBlocksOfItsMillimetreTwin) {
  std::mt19937 rng(GetParam());
  const Twins t = random_part(rng);
  const std::vector<MotionBlock> in = blocks_of(t.inch);
  const std::vector<MotionBlock> mm = blocks_of(t.mm);
  ASSERT_EQ(in.size(), mm.size()) << t.inch;
  int drills = 0;
  for (std::size_t k = 0; k < in.size(); ++k) {
    const int i = static_cast<int>(k);
    ASSERT_EQ(in[k].kind, mm[k].kind) << "block " << k;
    expect_near(in[k].target, mm[k].target, "target", i);
    expect_near(in[k].centre, mm[k].centre, "centre", i);
    EXPECT_NEAR(in[k].feed_mm_s, mm[k].feed_mm_s, 1e-3) << k;
    EXPECT_NEAR(in[k].depth_mm, mm[k].depth_mm, 1e-3) << k;
    EXPECT_NEAR(in[k].z_travel_mm, mm[k].z_travel_mm, 1e-3) << k;
    EXPECT_NEAR(in[k].final_radius_mm, mm[k].final_radius_mm, 1e-3) << k;
    EXPECT_EQ(in[k].dwell_s, mm[k].dwell_s) << "P is seconds in both";
    drills += in[k].kind == MotionKind::kDrill ? 1 : 0;
  }
  EXPECT_EQ(drills, 3);
}

INSTANTIATE_TEST_SUITE_P(Seeds, GcodeUnits, ::testing::Values(1u, 2u, 3u, 4u, 5u));

TEST(GcodeUnitsModal, G21SwitchesBackAndOneInchIsExactly25point4Millimetres) {
  const std::vector<MotionBlock> b = blocks_of("G20 G00 X1 Y-2\nG21 G00 X1 Y-2\nG20\nG00 Z0.5");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[0].target.x, 25.4);
  EXPECT_EQ(b[0].target.y, -50.8);
  EXPECT_EQ(b[1].target.x, 1.0) << "G21: millimetres again";
  EXPECT_EQ(b[2].target.z, 12.7) << "G20 alone on a line is modal";
}

TEST(GcodeUnitsModal, BothUnitCodesInOneBlockAreAConflict) {
  const GcodeResult r = interpret("G20 G21 G00 X1\nM30\n");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(joined(r).find("t.nc:1:5: 'G21' conflicts with 'G20'"), std::string::npos) << joined(r);
}

TEST(GcodeUnitsModal, AnInchValueBeyondTheSoftLimitIsRefusedAtItsWord) {
  const GcodeResult r = interpret("G20 G00 X4.5\nM30\n");  // 114.3 mm > 100
  ASSERT_FALSE(r.ok());
  EXPECT_NE(joined(r).find("t.nc:1:9:"), std::string::npos) << joined(r);
}

}  // namespace
}  // namespace edm::hmi::test
