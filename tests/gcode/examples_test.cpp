// The shipped part programs (examples/parts/) interpret cleanly against the test machine (E1
// drilling, negative, wear ratio 0.6, Tdr 8 µs; E2 finishing, positive; X/Y ±100, Z −60..20) and
// against the shipped drill-sim machine config, and do what their comments say.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "edm/machining/machine_config.hpp"
#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

namespace fs = std::filesystem;

const fs::path kExampleParts = fs::path(EDM_SOURCE_DIR) / "examples" / "parts";

GcodeResult interpret_part(const std::string& name,
                           const machining::MachineTables& tables = test_tables()) {
  std::ifstream in(kExampleParts / name, std::ios::binary);
  EXPECT_TRUE(in.good()) << name;
  std::ostringstream ss;
  ss << in.rdbuf();
  return interpret_gcode(ss.str(), name, tables);
}

// The part's blocks of `kind` (a test failure if it does not interpret cleanly).
std::vector<MotionBlock> part_blocks(const std::string& name, MotionKind kind) {
  const GcodeResult r = interpret_part(name);
  EXPECT_TRUE(r.ok()) << joined(r);
  return of_kind(r.blocks, kind);
}

TEST(GcodeExamples, EveryExampleInterpretsCleanly) {
  const machining::MachineTables drill_sim = machining::read_machine_tables(
      std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml");
  // The wire machine's parts (wire-*.nc) are its own: G41/G42 and cuts need machine.kind wire.
  const machining::MachineTables wire_sim = machining::read_machine_tables(
      std::string(EDM_SOURCE_DIR) + "/config/machines/wire-sim.yaml");
  int count = 0;
  for (const auto& e : fs::directory_iterator(kExampleParts)) {
    if (e.path().extension() != ".nc") continue;
    ++count;
    const std::string name = e.path().filename().string();
    const bool wire = name.rfind("wire-", 0) == 0;
    if (!wire) {
      const GcodeResult r = interpret_part(name);
      EXPECT_TRUE(r.ok()) << joined(r);
      EXPECT_FALSE(r.blocks.empty()) << name;
    }
    const GcodeResult s = interpret_part(name, wire ? wire_sim : drill_sim);
    EXPECT_TRUE(s.ok()) << joined(s);
    EXPECT_FALSE(s.blocks.empty()) << name;
  }
  EXPECT_GE(count, 5);
}

TEST(GcodeExamples, BlindHoleIsOneDrillTo20mmWithE1) {
  const auto d = part_blocks("blind-hole.nc", MotionKind::kDrill);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_DOUBLE_EQ(d[0].target.z, -20.0);
  EXPECT_EQ(d[0].condition, 1);
  // From Z0.5: 0.5 mm of air, then 20 mm eroded with θ 0.6 and A_hole/A_e 1.25 (test machine).
  EXPECT_NEAR(d[0].z_travel_mm, 20.5 + 0.6 * 1.25 * 20.0, 1e-9);
}

TEST(GcodeExamples, ThroughHoleGoesPastTheFarSide) {
  const auto d = part_blocks("through-hole.nc", MotionKind::kDrill);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_LT(d[0].target.z, -10.0);
}

TEST(GcodeExamples, DrillThenFinishSwitchesToPositiveAndOrbitsTo060) {
  const GcodeResult r = interpret_part("drill-then-finish.nc");
  ASSERT_TRUE(r.ok()) << joined(r);
  const auto d = of_kind(r.blocks, MotionKind::kDrill);
  const auto o = of_kind(r.blocks, MotionKind::kOrbitFinish);
  ASSERT_EQ(d.size(), 1u);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(d[0].condition, 1);
  EXPECT_EQ(o[0].condition, 2);
  EXPECT_DOUBLE_EQ(o[0].final_radius_mm, 0.60);
  // The orbit runs in the drilled hole, 0.2 mm off its bottom, about the hole's axis.
  EXPECT_EQ(o[0].centre, (machining::Vec3{d[0].target.x, d[0].target.y, d[0].target.z + 0.2}));
}

TEST(GcodeExamples, RowOfHolesHasFiveDrillsWithRapidsBetween) {
  const GcodeResult r = interpret_part("row-of-holes.nc");
  ASSERT_TRUE(r.ok()) << joined(r);
  const auto d = of_kind(r.blocks, MotionKind::kDrill);
  ASSERT_EQ(d.size(), 5u);
  for (std::size_t i = 0; i < d.size(); ++i) {
    EXPECT_DOUBLE_EQ(d[i].target.x, -20.0 + 10.0 * static_cast<double>(i));
    EXPECT_DOUBLE_EQ(d[i].target.z, -8.0);
  }
  EXPECT_GE(of_kind(r.blocks, MotionKind::kRapid).size(), 10u);
  EXPECT_TRUE(of_kind(r.blocks, MotionKind::kLinear).empty());
}

TEST(GcodeExamples, DieSinkPocketDrillsThenMovesInXyWithArcs) {
  const GcodeResult r = interpret_part("die-sink-pocket.nc");
  ASSERT_TRUE(r.ok()) << joined(r);
  EXPECT_EQ(of_kind(r.blocks, MotionKind::kDrill).size(), 1u);
  EXPECT_GE(of_kind(r.blocks, MotionKind::kArcCcw).size(), 4u);
  EXPECT_GE(of_kind(r.blocks, MotionKind::kArcCw).size(), 1u);
  EXPECT_GE(of_kind(r.blocks, MotionKind::kLinear).size(), 2u);
}

}  // namespace
}  // namespace edm::hmi::test
