// Wire cutting in the G-code dialect (issue 34, docs/gcode.md "Wire cutting"): armed moves are
// cuts, G41/G42/G40 offset the path by the condition's or the D word's offset with LinuxCNC's
// lead-in/lead-out rules, O/M98/M99 subprograms run the same contour for each skim, M00/M01.
// The compensated path is checked against geometry: every point of an offset line lies at the
// offset from its programmed line, corner arcs are centred on the programmed corner with the
// offset's radius, an inside corner ends where the two offset lines cross.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

machining::MachineTables wire_tables() {
  machining::MachineTables t;
  t.kind = machining::MachineKind::kWire;
  t.conditions.push_back({.e = 1, .name = "main", .offset_mm = 0.2});
  t.conditions.push_back({.e = 2, .name = "skim", .offset_mm = 0.15});
  t.conditions.push_back({.e = 3, .name = "no-offset"});
  return t;
}

GcodeResult wire(const std::string& body) {
  GcodeOptions o;
  o.start_mm = {-9, 0, 0};
  return interpret_gcode(body + "\nM30\n", "w.nc", wire_tables(), o);
}

std::vector<MotionBlock> moves(const GcodeResult& r) {
  std::vector<MotionBlock> out;
  for (const MotionBlock& b : r.blocks) {
    if (b.kind == MotionKind::kLinear || b.kind == MotionKind::kArcCw ||
        b.kind == MotionKind::kArcCcw) {
      out.push_back(b);
    }
  }
  return out;
}

const char* kSquare = "E1 F3\nG41 G01 X-5 Y0\nY5\nX5\nY-5\nX-5\nY0\nG40 X-9 Y0\n";

TEST(WireOffset, ASquareIsOffsetByTheConditionsOffsetWithArcsAtItsOutsideCorners) {
  const GcodeResult r = wire(kSquare);
  ASSERT_TRUE(r.ok()) << joined(r);
  const auto m = moves(r);
  // Lead-in, up, arc, right, arc, down, arc, left, arc, up to the lead-out's corner, lead-out.
  ASSERT_EQ(m.size(), 11u);
  const double d = 0.2;
  for (const MotionBlock& b : m) EXPECT_TRUE(b.cut);
  // The edges of the square lie at d outside it.
  EXPECT_NEAR(m[1].target.x, -5 - d, 1e-12);
  EXPECT_NEAR(m[1].target.y, 5, 1e-12);
  EXPECT_NEAR(m[3].target.y, 5 + d, 1e-12);
  EXPECT_NEAR(m[5].target.x, 5 + d, 1e-12);
  EXPECT_NEAR(m[7].target.y, -5 - d, 1e-12);
  // Every corner arc turns clockwise about the square's corner with radius d.
  for (std::size_t k : {2u, 4u, 6u, 8u}) {
    EXPECT_EQ(m[k].kind, MotionKind::kArcCw) << k;
    EXPECT_NEAR(std::fabs(m[k].centre.x), 5, 1e-12) << k;
    EXPECT_NEAR(std::fabs(m[k].centre.y), 5, 1e-12) << k;
    EXPECT_NEAR(std::hypot(m[k].target.x - m[k].centre.x, m[k].target.y - m[k].centre.y), d, 1e-12);
  }
  // The lead-in ends on the offset left edge, where the lead-in's own offset line crosses it.
  EXPECT_NEAR(m[0].target.x, -5 - d, 1e-12);
  EXPECT_NEAR(m[0].target.y, d * (4 - d) / 4, 1e-12);
  // The inside corner of the last edge and the lead-out: (−5 − d, −d); the lead-out ends on the
  // programmed (uncompensated) point.
  EXPECT_NEAR(m[9].target.x, -5 - d, 1e-12);
  EXPECT_NEAR(m[9].target.y, -d, 1e-12);
  EXPECT_DOUBLE_EQ(m[10].target.x, -9);
  EXPECT_DOUBLE_EQ(m[10].target.y, 0);
}

TEST(WireOffset, G42AndADWordPutTheWireOnTheOtherSide) {
  const GcodeResult r = wire("E3 F3\nG42 D0.1 G01 X-5 Y0\nY5\nX-4\nG40 X-4 Y8\n");
  ASSERT_TRUE(r.ok()) << joined(r);
  // Up the edge (line 3) with the wire on the right: x = −5 + 0.1; the corner (up, then right)
  // is inside: the edge ends where the offset lines cross. The lead-in's corner (right, then
  // up) is outside: an arc, counter-clockwise, about (−5, 0).
  int seen = 0;
  for (const MotionBlock& b : moves(r)) {
    if (b.line == 3 && b.kind == MotionKind::kLinear) {
      ++seen;
      EXPECT_NEAR(b.target.x, -4.9, 1e-12);
      EXPECT_NEAR(b.target.y, 4.9, 1e-12);
    }
    if (b.line == 3 && b.kind == MotionKind::kArcCcw) {
      ++seen;
      EXPECT_NEAR(b.centre.x, -5, 1e-12);
      EXPECT_NEAR(b.centre.y, 0, 1e-12);
    }
  }
  EXPECT_EQ(seen, 2);
}

// Seeded random convex polygons (counter-clockwise, G42 keeps the wire outside): every offset
// edge is parallel to its edge at the offset, every corner is an arc of the offset's radius.
TEST(WireOffset, RandomConvexPolygonsAreOffsetExactly) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> radius(3.0, 6.0), offset(0.05, 0.3), turn(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 3 + trial % 6;
    const double rr = radius(rng), phase = turn(rng);
    std::vector<std::pair<double, double>> p;
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * std::numbers::pi * (k + phase) / n;
      p.emplace_back(rr * std::cos(a), rr * std::sin(a));
    }
    const double d = std::round(offset(rng) * 1e4) / 1e4;  // as the program writes it
    char line[96];
    std::string prog = "E3 F3\n";
    // The lead-in from the centre to the middle of the last edge.
    const double mx = (p[0].first + p.back().first) / 2, my = (p[0].second + p.back().second) / 2;
    std::snprintf(line, sizeof line, "G00 X0 Y0\nG42 D%.4f G01 X%.6f Y%.6f\n", d, mx, my);
    prog += line;
    for (const auto& [x, y] : p) {
      std::snprintf(line, sizeof line, "X%.6f Y%.6f\n", x, y);
      prog += line;
    }
    std::snprintf(line, sizeof line, "X%.6f Y%.6f\nG40 X0 Y0\n", mx, my);
    prog += line;
    const GcodeResult r = wire(prog);
    ASSERT_TRUE(r.ok()) << joined(r) << prog;
    const auto m = moves(r);
    // The lead-in and lead-out meet the contour at outside corners too (at the edge's middle).
    int vertex_arcs = 0;
    for (const MotionBlock& b : m) {
      ASSERT_NE(b.kind, MotionKind::kArcCw) << prog;
      if (b.kind != MotionKind::kArcCcw) continue;
      EXPECT_NEAR(std::hypot(b.target.x - b.centre.x, b.target.y - b.centre.y), d, 1e-9);
      if (std::fabs(std::hypot(b.centre.x, b.centre.y) - rr) < 1e-5) ++vertex_arcs;
    }
    EXPECT_EQ(vertex_arcs, n) << prog;
    // Every offset edge lies at d outside its edge: its end's distance to the edge's line.
    for (std::size_t k = 0; k + 1 < m.size(); ++k) {
      if (m[k].kind != MotionKind::kLinear || m[k].line < 4 || m[k].line > 3 + n) continue;
      const int v = m[k].line - 4;  // the vertex this edge ends on
      const auto [x0, y0] = p[static_cast<std::size_t>((v + n - 1) % n)];
      const auto [x1, y1] = p[static_cast<std::size_t>(v)];
      const double len = std::hypot(x1 - x0, y1 - y0);
      const double dist =
          ((x1 - x0) * (m[k].target.y - y0) - (y1 - y0) * (m[k].target.x - x0)) / len;
      EXPECT_NEAR(dist, -d, 1e-5) << "edge of line " << m[k].line << "\n" << prog;
    }
  }
}

TEST(WireOffset, AConcaveArcSmallerThanTheOffsetIsRefusedAtItsWord) {
  // A pocket's inside arc of radius 0.1 under an offset of 0.2 (G41 on a counter-clockwise arc
  // puts the wire toward its centre).
  const GcodeResult r = wire("E1 F3\nG41 G01 X-5 Y0\nG03 X-5.2 Y0.2 I0 J0.2\nG40 G01 X-9 Y0\n");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.messages()[0].rfind("w.nc:3:1: the wire offset 0.200 mm cannot be applied", 0), 0u)
      << joined(r);
}

TEST(WireOffset, BadUsesAreRefusedWithTheirPlace) {
  struct Case {
    std::string body;
    std::string starts;
  };
  const Case cases[] = {
      {"E3 F3\nG41 G01 X-5 Y0\n", "w.nc:2:1: 'G41' needs an offset"},
      {"E1 F3\nG41 G02 X-8 Y1 I1 J0\n", "w.nc:2:5: the wire offset is switched on on a straight"},
      {"E1 F3\nG41 G01 X-8.9 Y0\n", "w.nc:2:5: the lead-in move must be longer"},
      {"E1 F3\nG41 G01 X-5 Y0\nY5\n", "w.nc:5:1: the wire offset (G41/G42) is still on"},
      {"E1 F3\nG41 G01 X-5 Y0\nG41 Y5\n", "w.nc:3:1: 'G41' while the wire offset is on"},
      {"E1 F3\nG41 G01 X-5 Y0\nG00 Y5\n", "w.nc:3:1: G00 while the wire offset is on"},
      {"E1 F3\nG01 X-5 Z1\n", "w.nc:2:9: a wire cut moves X and Y only"},
      {"E1 F3\nD0.2 G01 X-5\n", "w.nc:2:1: 'D0.2' is only used by G41/G42"},
      {"E1 F3\nG41 D20 G01 X-5\n", "w.nc:2:5: wire offset 'D20' must be > 0"},
  };
  for (const Case& c : cases) {
    const GcodeResult r = wire(c.body);
    ASSERT_FALSE(r.ok()) << c.body;
    EXPECT_EQ(r.messages()[0].rfind(c.starts, 0), 0u) << c.body << "\n" << joined(r);
  }
}

TEST(WireOffset, TheOffsetIsForWireMachinesOnly) {
  EXPECT_EQ(first_error("G41 D0.2 G01 X1 F60"),
            "t.nc:1:1: 'G41' (wire offset) is for wire machines (machine.kind: wire)");
}

TEST(Subprograms, M98RunsTheBodyWithEachPasssConditionAndL) {
  const GcodeResult r = wire(
      "E1 F3 M98 P100\nE2 F6 M98 P100 L2\nM00\nM01\nM30\nO100\nG41 G01 X-5 Y0\nY5\nX-4\n"
      "G40 X-9 Y0\nM99\n");
  // "M30" is appended by wire() after the program's own: the program's is the end.
  ASSERT_FALSE(r.ok());  // the appended M30 follows the end
  const GcodeResult ok = interpret_gcode(
      "E1 F3 M98 P100\nE2 F6 M98 P100 L2\nM00\nM01\nM30\nO100\nG41 G01 X-5 Y0\nY5\nX-4\n"
      "G40 X-9 Y0\nM99\n",
      "w.nc", wire_tables(), GcodeOptions{.start_mm = {-9, 0, 0}});
  ASSERT_TRUE(ok.ok()) << joined(ok);
  // Three passes; the first's up-edge at −5.2 (E1), the others' at −5.15 (E2).
  std::vector<double> left_edges;
  for (const MotionBlock& b : ok.blocks) {
    if (b.kind == MotionKind::kLinear && b.line == 8) left_edges.push_back(b.target.x);
  }
  ASSERT_EQ(left_edges.size(), 3u);
  EXPECT_NEAR(left_edges[0], -5.2, 1e-12);
  EXPECT_NEAR(left_edges[1], -5.15, 1e-12);
  EXPECT_NEAR(left_edges[2], -5.15, 1e-12);
  const auto stops = of_kind(ok.blocks, MotionKind::kProgramStop);
  ASSERT_EQ(stops.size(), 2u);
  EXPECT_FALSE(stops[0].on);
  EXPECT_TRUE(stops[1].on);
}

TEST(Subprograms, BadDefinitionsAndCallsAreRefused) {
  struct Case {
    std::string text;
    std::string starts;
  };
  const Case cases[] = {
      {"M98 P7\nM30\n", "w.nc:1:5: M98 'P7': this program has no subprogram O7"},
      {"M98 P1\nM30\nO1\nM98 P1\nM99\n", "w.nc:4:1: subprogram calls nest deeper than 8"},
      {"M99\nM30\n", "w.nc:1:1: M99 outside a subprogram"},
      {"M30\nO1\nG01 X1\n", "w.nc:2:1: subprogram O1 has no M99"},
      {"M30\nO1\nO2\nM99\n", "w.nc:3:1: subprogram definitions do not nest"},
      {"M30\nO1 G01\nM99\n", "w.nc:2:4: O<n> opens a subprogram and stands alone"},
      {"M30\nO1\nM99\nO1\nM99\n", "w.nc:4:1: subprogram O1 is defined twice"},
      {"M98 P1 L0\nM30\nO1\nM99\n", "w.nc:1:8: repeat count 'L0' must be a whole number"},
      {"G01 X1 L2 F60\nM30\n", "w.nc:1:8: 'L2' is only used by M98"},
  };
  for (const Case& c : cases) {
    const GcodeResult r = interpret_gcode(c.text, "w.nc", wire_tables(), {});
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_EQ(r.messages()[0].rfind(c.starts, 0), 0u) << c.text << "\n" << joined(r);
  }
}

TEST(Subprograms, ACallBombIsBoundedNotAHang) {
  // Eight levels of L1000 would run 1000^8 lines; the interpreter stops at its bound (100 000).
  std::string text = "M98 P1 L1000\nM30\n";
  for (int k = 1; k <= 8; ++k) {
    text += "O" + std::to_string(k) + "\n";
    text += k < 8 ? "M98 P" + std::to_string(k + 1) + " L1000\n" : "G04 P0\n";
    text += "M99\n";
  }
  const GcodeResult r = interpret_gcode(text, "w.nc", wire_tables(), {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(joined(r).find("run more than 100000 lines"), std::string::npos) << joined(r);
}

}  // namespace
}  // namespace edm::hmi::test
