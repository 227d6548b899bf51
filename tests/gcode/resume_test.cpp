// Run from a block (hmi/resume.hpp, docs/gcode.md "Resuming a program"): the re-approach
// prologue, the modal state it replays, the drilling block's remaining depth by eq. (10), and the
// lines that cannot be resumed. Properties are checked on every line of every shipped example.
#include "edm/hmi/resume.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "edm/machining/machine_config.hpp"
#include "edm/machining/program_check.hpp"
#include "gcode_fixture.hpp"

namespace edm::hmi::test {
namespace {

namespace fs = std::filesystem;
using machining::Vec3;

// Line numbers matter here: line 1 is "%".
constexpr const char* kDrillThenFinish =
    "%\n"               // 1
    "G17 G21 G90\n"     // 2
    "G00 Z5\n"          // 3
    "G00 X-20 Y10\n"    // 4
    "M03 M08\n"         // 5
    "G00 Z0.5\n"        // 6
    "E1\n"              // 7
    "G01 Z-15 F60\n"    // 8
    "G00 Z-14.8\n"      // 9
    "E2\n"              // 10
    "G160 R0.60 F30\n"  // 11
    "E0\n"              // 12
    "G00 Z5\n"          // 13
    "M05 M09\n"         // 14
    "M30\n"             // 15
    "%\n";

GcodeResult program(const char* text = kDrillThenFinish, Vec3 now = {3.0, 4.0, 2.0}) {
  GcodeOptions o;
  o.start_mm = now;
  GcodeResult r = interpret(text, o);
  EXPECT_TRUE(r.ok()) << joined(r);
  return r;
}

/// The prologue's properties, whatever the program: only rapids before the modal blocks, up
/// first (X/Y unchanged), then over at the clearance, down to the block's start; the condition
/// last; nothing in it discharges.
void expect_safe_prologue(const GcodeResult& g, const ResumePlan& p, const std::string& where) {
  ASSERT_TRUE(p.ok()) << where << ": " << p.error;
  ASSERT_EQ(p.prologue, 6u) << where;
  ASSERT_EQ(p.blocks.size(), p.prologue + g.blocks.size() - p.first) << where;
  ASSERT_EQ(p.frames.size(), p.blocks.size()) << where;
  const Vec3 now = g.start_mm;
  const Vec3 start = block_starts(g)[p.first];
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(p.blocks[i].kind, MotionKind::kRapid) << where << " block " << i;
    EXPECT_EQ(p.blocks[i].condition, 0) << where;  // nothing armed while moving
  }
  EXPECT_EQ(p.blocks[0].target, (Vec3{now.x, now.y, p.clearance_z_mm})) << where;
  EXPECT_GE(p.clearance_z_mm, now.z) << where;  // straight up (or stay), never down
  EXPECT_GE(p.clearance_z_mm, start.z) << where;
  EXPECT_EQ(p.blocks[1].target, (Vec3{start.x, start.y, p.clearance_z_mm})) << where;
  EXPECT_EQ(p.blocks[2].target, start) << where;
  EXPECT_EQ(p.blocks[3].kind, MotionKind::kRotation) << where;
  EXPECT_EQ(p.blocks[4].kind, MotionKind::kFlushing) << where;
  EXPECT_EQ(p.blocks[5].kind, MotionKind::kCondition) << where;
  for (std::size_t i = 0; i < p.prologue; ++i) {
    EXPECT_EQ(p.blocks[i].target, i < 2 ? p.blocks[i].target : start) << where;
    EXPECT_EQ(p.blocks[i].line, 0) << where;  // not a program line
  }
  // The rest is the program from `first` on, unchanged but for the drilling block's depth.
  for (std::size_t i = p.first; i < g.blocks.size(); ++i) {
    const std::size_t j = p.prologue + i - p.first;
    if (p.drill && j == *p.drill) continue;
    EXPECT_EQ(p.blocks[j], g.blocks[i]) << where << " block " << i;
  }
  EXPECT_EQ(p.blocks[p.prologue].line, p.line) << where;
}

TEST(Resume, ReapproachesTheDrillingBlockAndReplaysTheModalState) {
  const GcodeResult g = program();
  const ResumePlan p = plan_resume(g, test_tables(), 8);
  expect_safe_prologue(g, p, "line 8");
  EXPECT_EQ(p.line, 8);
  EXPECT_EQ(g.blocks[p.first].kind, MotionKind::kDrill);
  EXPECT_DOUBLE_EQ(p.clearance_z_mm, 5.0);  // G00 Z5 of line 3
  EXPECT_EQ(p.blocks[2].target, (Vec3{-20.0, 10.0, 0.5}));
  EXPECT_TRUE(p.blocks[3].on);          // M03
  EXPECT_TRUE(p.blocks[4].on);          // M08
  EXPECT_EQ(p.blocks[5].condition, 1);  // E1 re-armed
  ASSERT_TRUE(p.drill.has_value());
  EXPECT_EQ(*p.drill, p.prologue);
  // A new hole: the travel is the interpreter's own.
  EXPECT_EQ(p.blocks[*p.drill], g.blocks[p.first]);
}

TEST(Resume, TheDrillingBlockGetsTheDepthDoneAndTheTravelForWhatIsLeft) {
  const GcodeResult g = program();
  const ResumePlan p = plan_resume(g, test_tables(), 8, 6.0);
  expect_safe_prologue(g, p, "line 8, 6 mm done");
  ASSERT_TRUE(p.drill.has_value());
  const MotionBlock& d = p.blocks[*p.drill];
  EXPECT_DOUBLE_EQ(d.depth_done_mm, 6.0);
  EXPECT_DOUBLE_EQ(p.depth_done_mm, 6.0);
  EXPECT_DOUBLE_EQ(d.depth_mm, 15.0);
  // Eq. (10) for lz − done = 9 mm (θ 0.6, area ratio 1.25), the axis still travels the block:
  // 0.5 of air, 6 mm of hole, 9 mm of work.
  EXPECT_NEAR(d.z_travel_mm, 15.5 + 0.6 * 1.25 * 9.0, 1e-9);
  EXPECT_EQ(d.target, g.blocks[p.first].target);
  // The whole depth done: nothing to erode, the travel is the block.
  EXPECT_NEAR(plan_resume(g, test_tables(), 8, 15.0).blocks[*p.drill].z_travel_mm, 15.5, 1e-9);
}

TEST(Resume, AtALineWithSeveralBlocksTheDrillingBlockOnItTakesTheDepth) {
  const GcodeResult g = program("G00 Z0.5\nM08\nE1 G01 Z-10 F60\nE0\nM30");
  const ResumePlan p = plan_resume(g, test_tables(), 3, 4.0);
  expect_safe_prologue(g, p, "line 3");
  EXPECT_EQ(p.blocks[p.prologue].kind, MotionKind::kCondition);  // the line's E1 first
  ASSERT_TRUE(p.drill.has_value());
  EXPECT_EQ(*p.drill, p.prologue + 1);
  EXPECT_EQ(p.blocks[5].condition, 0);  // nothing was armed before line 3
  EXPECT_FALSE(p.blocks[3].on);
  EXPECT_TRUE(p.blocks[4].on);
  EXPECT_NEAR(p.blocks[*p.drill].z_travel_mm, 10.5 + 0.6 * 1.25 * 6.0, 1e-9);
}

TEST(Resume, NIsTheSourceLineTheFirstBlockAtOrAfterIt) {
  const GcodeResult g = program();
  // Line 2 has no block (modal codes only): the first block at or after it is line 3's rapid.
  const ResumePlan p = plan_resume(g, test_tables(), 2);
  expect_safe_prologue(g, p, "line 2");
  EXPECT_EQ(p.line, 3);
  EXPECT_EQ(p.first, 0u);
  // From the top, the clearance is where the electrode is or the first block's start.
  EXPECT_DOUBLE_EQ(p.clearance_z_mm, 2.0);
}

TEST(Resume, TheClearanceIsTheHighestZSoFarAndAtLeastWhereTheElectrodeIs) {
  // Electrode now at Z 30 (above everything): the prologue does not go down first.
  const GcodeResult high = program(kDrillThenFinish, {0.0, 0.0, 30.0});
  EXPECT_DOUBLE_EQ(plan_resume(high, test_tables(), 9).clearance_z_mm, 30.0);
  // Electrode stuck in the hole at Z −7 after an interruption: straight up to Z5 first.
  const GcodeResult low = program(kDrillThenFinish, {-20.0, 10.0, -7.0});
  const ResumePlan p = plan_resume(low, test_tables(), 9);
  expect_safe_prologue(low, p, "line 9 from inside the hole");
  EXPECT_EQ(p.blocks[0].target, (Vec3{-20.0, 10.0, 5.0}));
}

TEST(Resume, WorkFramesCarryOver) {
  GcodeOptions o;
  o.offsets.frame[1] = {50.0, 0.0, -30.0};
  o.start_mm = {0.0, 0.0, 10.0};
  const GcodeResult g = interpret("G55\nG00 X1 Y1 Z2\nG00 Z0.5\nE1\nG01 Z-6 F60\nE0\nM30", o);
  ASSERT_TRUE(g.ok()) << joined(g);
  const ResumePlan p = plan_resume(g, test_tables(), 5, 2.0);
  expect_safe_prologue(g, p, "G55 line 5");
  EXPECT_DOUBLE_EQ(p.clearance_z_mm, 10.0);  // machine coordinates: start 10 > G55 Z2 (−28)
  EXPECT_EQ(p.blocks[2].target, (Vec3{51.0, 1.0, -29.5}));
  EXPECT_EQ(p.frames[0].frame, 1);
  EXPECT_NEAR(p.blocks[*p.drill].z_travel_mm, 6.5 + 0.6 * 1.25 * 4.0, 1e-9);
}

// A queue that goes on after an electrode change (issue 33): the frame's Z was set with a 300 mm
// electrode, the one in the spindle now is longer or shorter. The prologue is in the resumed
// block's compensation, so the approach ends where that block begins wherever the job puts it:
// the program passes the runtime's check with the new length (a drill from an uncompensated
// approach did not: "a drilling block must move Z down"), and the first rapid, compensated, goes
// from where the spindle is straight up or stays (never down, never to the limit needlessly).
TEST(Resume, AfterAnElectrodeChangeTheApproachIsCompensatedLikeTheResumedBlock) {
  for (const double now_mm : {308.0, 292.0}) {
    GcodeOptions o;
    o.offsets.frame[0] = {0.0, 0.0, -0.2};
    o.offsets.z_electrode_mm[0] = 300.0;
    o.offsets.electrode_mm = now_mm;
    o.start_mm = {-45.0, -45.0, 19.0};  // parked high over the tool setter
    const GcodeResult g = interpret(kDrillThenFinish, o);
    ASSERT_TRUE(g.ok()) << joined(g);
    const ResumePlan p = plan_resume(g, test_tables(), 8);
    ASSERT_TRUE(p.ok()) << p.error;
    const double comp = now_mm - 300.0;
    for (std::size_t i = 0; i < p.prologue; ++i) {
      EXPECT_EQ(p.blocks[i].electrode_ref_mm, 300.0) << now_mm << " block " << i;
    }
    EXPECT_DOUBLE_EQ(p.blocks[0].target.z + comp, 19.0) << now_mm << ": straight up or stay";
    EXPECT_EQ(p.blocks[2].target, g.blocks[p.first - 1].target) << "ends where line 8 begins";
    machining::ProgramCheckOptions check;
    check.electrode_mm = now_mm;
    const auto issues = machining::check_program(p.blocks, test_tables(), o.start_mm, check);
    EXPECT_TRUE(issues.empty()) << now_mm << ": " << (issues.empty() ? "" : issues[0].message);
  }
}

TEST(Resume, RefusesWhatCannotBeResumed) {
  const GcodeResult g = program();
  EXPECT_EQ(plan_resume(g, test_tables(), 11).error,
            "line 11 is a G160 orbit-finishing cycle, which cannot be resumed part-way: resume "
            "from an earlier line to run the cycle whole");
  EXPECT_EQ(plan_resume(g, test_tables(), 15).error,
            "line 15 is the program end: nothing to resume");
  EXPECT_EQ(plan_resume(g, test_tables(), 16).error,
            "line 16 is past the program's last block (line 15)");
  EXPECT_EQ(plan_resume(g, test_tables(), 0).error, "line 0: lines are numbered from 1");
  EXPECT_EQ(plan_resume(g, test_tables(), 9, 1.0).error,
            "line 9 has no drilling block to take a depth of 1.000 mm");
  EXPECT_EQ(plan_resume(g, test_tables(), 8, 15.5).error,
            "the hole is already 15.500 mm deep; line 8 drills to 15.000 mm: nothing left to "
            "drill, resume from the next line");
  EXPECT_EQ(plan_resume(g, test_tables(), 8, -1.0).error,
            "the depth already drilled must be a number >= 0 mm, not -1.000");
  GcodeResult bad = g;
  bad.errors.push_back({3, 1, "x"});
  EXPECT_FALSE(plan_resume(bad, test_tables(), 8).ok());
}

TEST(Resume, EveryLineOfEveryExampleResumesSafelyOrSaysWhyNot) {
  const machining::MachineTables tables = machining::read_machine_tables(
      std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml");
  int resumed = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(EDM_SOURCE_DIR) / "examples/parts")) {
    // The wire machine's parts are not the drill's (their resume after a wire break: issue 34,
    // not built yet).
    if (entry.path().filename().string().rfind("wire-", 0) == 0) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    GcodeOptions o;
    o.start_mm = {1.0, -2.0, 3.0};
    const GcodeResult g = interpret_gcode(ss.str(), entry.path().filename().string(), tables, o);
    ASSERT_TRUE(g.ok()) << joined(g);
    for (std::int32_t line = 1; line <= g.blocks.back().line + 1; ++line) {
      const ResumePlan p = plan_resume(g, tables, line);
      const std::string where = entry.path().filename().string() + ":" + std::to_string(line);
      if (!p.ok()) {
        const MotionBlock* b = nullptr;
        for (const MotionBlock& m : g.blocks) {
          if (m.line >= line) {
            b = &m;
            break;
          }
        }
        // Only the end, past it, or an orbit line is refused.
        EXPECT_TRUE(b == nullptr || b->kind == MotionKind::kEnd ||
                    b->kind == MotionKind::kOrbitFinish ||
                    p.error.find("G160") != std::string::npos)
            << where << ": " << p.error;
        continue;
      }
      expect_safe_prologue(g, p, where);
      // The runtime's commit check accepts it, from where the electrode is.
      EXPECT_TRUE(machining::check_program(p.blocks, tables, g.start_mm).empty()) << where;
      ++resumed;
    }
  }
  EXPECT_GT(resumed, 30);
}

}  // namespace
}  // namespace edm::hmi::test
