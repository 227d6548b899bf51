// Issue 33 item 1, end to end on the simulated drill machine: the electrode's length is
// compensated as it wears. The operator touches the work's surface off once (G54 Z, which
// records the electrode length then); two jobs drill a blind hole each, at two places, without
// another touch. The first hole wears the electrode by millimetres; the second job's rapid to
// Z0.5 must still put the tip 0.5 mm above the surface (the simulator's truth), and its hole
// must still be as deep as programmed. Before issue 33 the second job stopped its rapid that
// much too high and fed through air.
//
// Over seeds and hole depths: a property of the compensation, not of one example.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "edm/hmi/gcode.hpp"
#include "operator_rig.hpp"

namespace edm::test {
namespace {

/// A blind hole `depth` mm deep at work (x, 0): the E1 block is on line 7, after the rapid to
/// Z0.5 above the surface.
std::string hole_at(double x, double depth) {
  return "%\nG17 G21 G90 G54\nG00 Z5.0\nG00 X" + std::to_string(x) +
         " Y0\nM03 M08\nG00 Z0.5\nE1\nG01 Z-" + std::to_string(depth) +
         " F60\nE0\nG00 Z5.0\nM05 M09\nM30\n%\n";
}
constexpr std::int64_t kConditionLine = 7;

/// What `offset.get` gives the HMI: the frames, each Z with its electrode length, and the
/// electrode's length now.
hmi::WorkOffsets offsets_of(rt::Runtime& r) {
  hmi::WorkOffsets o;
  const auto frames = r.work_offsets().all();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    o.frame[i] = {frames[i].x, frames[i].y, frames[i].z};
    o.z_electrode_mm[i] = frames[i].z_electrode_mm;
  }
  o.electrode_mm = r.electrode().length_mm();
  return o;
}

std::vector<machining::MotionBlock> interpret(OperatorRig& m, const std::string& text) {
  hmi::GcodeOptions go;
  go.start_mm = {m.read("io.x_mm"), m.read("io.y_mm"), m.read("io.z_mm")};
  go.offsets = offsets_of(*m.runtime);
  const hmi::GcodeResult g = hmi::interpret_gcode(text, "hole.nc", m.runtime->tables(), go);
  EXPECT_TRUE(g.ok()) << (g.ok() ? "" : g.messages().front());
  return g.blocks;
}

struct Case {
  int seed;
  double depth_mm;
};

class ElectrodeCompensation : public ::testing::TestWithParam<Case> {};

TEST_P(ElectrodeCompensation, TheSecondJobFindsTheSurfaceWithAShorterElectrodeAndNoNewTouch) {
  const Case c = GetParam();
  OperatorRig m("start_gap_um: 4000", "", c.seed);
  rt::Electrode& electrode = m.runtime->electrode();
  ASSERT_TRUE(electrode.known()) << "drill-sim's machine.electrode gives the first length";
  const double length_at_touch = electrode.length_mm();

  // The operator touches the surface off and sets G54 there (what `edmhmi touch z --set G54`
  // does through offset.set, which records the electrode's length with the new Z).
  const rt::ManualResult tz = m.touch(rt::TouchTarget::kZ);
  ASSERT_TRUE(tz.ok) << rt::to_string(tz.error);
  m.runtime->work_offsets().set(0, m.read("io.x_mm"), m.read("io.y_mm"), tz.z,
                                electrode.length_mm());
  ASSERT_EQ(m.runtime->work_offsets().get(0).z_electrode_mm, length_at_touch);

  // Job 1: a hole at work X0. The estimate follows the wear it counts.
  ASSERT_TRUE(m.start_program(interpret(m, hole_at(0.0, c.depth_mm)), rt::JobSlot::kMain));
  ASSERT_TRUE(m.run_to_end()) << "job 1";
  const double lost_mm = length_at_touch - electrode.length_mm();
  const double true_lost_mm = m.truth().electrode_length_mm < length_at_touch
                                  ? length_at_touch - m.truth().electrode_length_mm
                                  : 0.0;
  EXPECT_GT(lost_mm, 0.3 * c.depth_mm) << "a blind hole wears the electrode by millimetres";
  EXPECT_NEAR(lost_mm, true_lost_mm, 0.03) << "the estimate is the wear compensator's";
  EXPECT_NEAR(m.read("cnc.job.electrode_mm"), electrode.length_mm(), 1e-9);

  // Job 2, interpreted with the machine's offsets as the HMI does, at work X3, no new touch.
  ASSERT_TRUE(m.start_program(interpret(m, hole_at(3.0, c.depth_mm)), rt::JobSlot::kMain));
  const rt::TimePoint give_up = m.now + std::chrono::seconds(60);
  while (m.read("cnc.job.line") != static_cast<double>(kConditionLine) && m.now < give_up) {
    m.run_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(m.read("cnc.job.line"), static_cast<double>(kConditionLine));
  // The rapid to Z0.5 has ended (the job waits in position before its next block): the tip is
  // 0.5 mm above the untouched surface, within the wear estimate's error.
  const double tip_um = m.truth().gap_um;
  EXPECT_NEAR(m.read("cnc.job.z_comp_mm"), -lost_mm, 1e-9) << "Z moved by the length lost";
  EXPECT_NEAR(tip_um, 500.0, 40.0) << "without compensation: " << 500.0 + lost_mm * 1e3 << " um";
  ASSERT_TRUE(m.run_to_end()) << "job 2";
  const double depth_err_um = (m.truth().hole_depth_mm - c.depth_mm) * 1e3;
  std::printf(
      "seed %d, %.0f mm holes: the first wore %.4f mm (truth %.4f); the second job's Z0.5 put the "
      "tip %.1f um above the surface; its hole %+.1f um off the programmed depth\n",
      c.seed, c.depth_mm, lost_mm, true_lost_mm, tip_um, depth_err_um);
  EXPECT_NEAR(depth_err_um, 0.0, 20.0);
  EXPECT_EQ(m.runtime->machine().state(), rt::MachineState::kReady);
}

INSTANTIATE_TEST_SUITE_P(SeedsAndDepths, ElectrodeCompensation,
                         ::testing::Values(Case{1, 6.0}, Case{2, 4.0}, Case{3, 8.0}),
                         [](const ::testing::TestParamInfo<Case>& i) {
                           return "seed" + std::to_string(i.param.seed) + "_" +
                                  std::to_string(static_cast<int>(i.param.depth_mm)) + "mm";
                         });

}  // namespace
}  // namespace edm::test
