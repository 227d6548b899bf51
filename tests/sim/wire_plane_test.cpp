// The wire machine's plate in plan view (sim/wire_plane.hpp, docs/simulator.md §7b), checked
// against geometry: the clearance in the start hole is the hole's radius less the distance to
// its centre, the field's edges are the plate's and the hole's, the thickness follows the step
// and the void, and erosion conserves volume (what the field lost equals what was eroded).
#include "edm/sim/wire_plane.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

namespace edm::sim {
namespace {

WirePlaneGeometry plate() {
  WirePlaneGeometry g;
  g.x_min_mm = -5.0;
  g.x_max_mm = 5.0;
  g.y_min_mm = -5.0;
  g.y_max_mm = 5.0;
  g.thickness_mm = 20.0;
  g.hole_x_mm = -2.0;
  g.hole_d_mm = 1.0;
  g.step_x_mm = 2.0;
  g.step_mm = 10.0;
  g.void_x_mm = 0.0;
  g.void_y_mm = 3.0;
  g.void_d_mm = 2.0;
  g.void_height_mm = 5.0;
  return g;
}

TEST(WirePlane, TheClearanceInTheStartHoleIsItsRadiusLessTheOffCentre) {
  const WirePlane p(plate());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> r(0.0, 0.4), a(0.0, 2.0 * std::numbers::pi);
  for (int k = 0; k < 200; ++k) {
    const double rr = r(rng), aa = a(rng);
    EXPECT_NEAR(p.clearance_mm(-2.0 + rr * std::cos(aa), rr * std::sin(aa)), 0.5 - rr, 2e-4) << rr;
  }
  EXPECT_LT(p.clearance_mm(0.0, 0.0), 0.0) << "in the material";
}

TEST(WirePlane, TheTruthMeasuresThePlatesAndTheHolesEdges) {
  const WirePlane p(plate());
  EXPECT_NEAR(p.edge_along_mm(0.0, 0.0, 1.0, 0.0, 20.0), 5.0, 1e-4);   // the plate's edge
  EXPECT_NEAR(p.edge_along_mm(0.0, 0.0, -1.0, 0.0, 20.0), 1.5, 1e-4);  // the hole's wall
  EXPECT_NEAR(p.edge_along_mm(0.0, 0.0, 0.0, -1.0, 20.0), 5.0, 1e-4);
  EXPECT_LT(p.edge_along_mm(-2.0, 0.0, 1.0, 0.0, 20.0), 0.0) << "from the void: none";
}

TEST(WirePlane, TheThicknessFollowsTheStepAndTheVoid) {
  const WirePlane p(plate());
  EXPECT_DOUBLE_EQ(p.cut_thickness_mm(0.0, 0.0), 20.0);
  EXPECT_DOUBLE_EQ(p.cut_thickness_mm(2.5, 0.0), 30.0);
  EXPECT_DOUBLE_EQ(p.cut_thickness_mm(0.0, 3.5), 15.0);
  EXPECT_DOUBLE_EQ(p.cut_thickness_mm(0.0, 4.5), 20.0);
}

// A main cut from the plate's edge in +X, eroding as it goes with a 20 µm gap: the field loses the
// volume that was eroded (to the grid's resolution: cells counted whole), the front advances by
// V / (H · kerf), and the kerf behind the wire is symmetric and wider than the wire.
TEST(WirePlane, AMainCutConservesVolumeAndOpensAKerf) {
  WirePlaneGeometry g = plate();
  g.hole_d_mm = 0.0;
  g.step_mm = 0.0;
  g.void_d_mm = 0.0;
  WirePlane p(g);
  const double r_wire = 0.125, reach = r_wire + 0.06, v = 1e-3;  // mm³ per erosion
  double x = -5.0 - r_wire - 0.02, eroded = 0.0, removed_at = 0.0, eroded_at = 0.0, x_at = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const double d0 = p.clearance_mm(x, 0.0);
    ASSERT_EQ(p.erode(x, 0.0, reach, v), 0.0) << "material within reach";
    eroded += v;
    // Erosion never brings material closer (to the clearance cache's 0.25 µm of reuse).
    EXPECT_GE(p.clearance_mm(x, 0.0), d0 - 3e-4);
    while (p.clearance_mm(x, 0.0) - r_wire > 0.02) x += 0.0005;  // the servo: a 20 µm gap
    if (k == 999) {                                              // the start's transient is over
      removed_at = p.removed_mm3();
      eroded_at = eroded;
      x_at = x;
    }
  }
  const double removed = p.removed_mm3() - removed_at, by_pulses = eroded - eroded_at;
  std::printf("main cut: %.3f mm advanced, removed %.4f of %.4f mm^3 eroded\n", x - x_at, removed,
              by_pulses);
  EXPECT_NEAR(removed, by_pulses, 0.05 * by_pulses);
  const double up = p.edge_along_mm(x - 0.3, 1.0, 0.0, -1.0, 2.0);
  const double down = p.edge_along_mm(x - 0.3, -1.0, 0.0, 1.0, 2.0);
  EXPECT_NEAR(up, down, 0.002);
  EXPECT_GT(2.0 - up, 2.0 * r_wire) << "the kerf is wider than the wire";
}

}  // namespace
}  // namespace edm::sim
