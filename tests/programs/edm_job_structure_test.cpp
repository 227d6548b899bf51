// The job's structure (issue 32): its cycles and arbiter are children whose inputs the job
// drives (Input::drive), with no output of the job that only feeds a child; a YAML wire into a
// driven input is refused at the wire.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include "sim_machine.hpp"

namespace edm::test {
namespace {

const std::string kDir = std::string(EDM_SOURCE_DIR) + "/config/machines/";

std::string drill_sim_text() {
  std::ifstream in(kDir + "drill-sim.yaml");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(EdmJobStructure, TheJobsChildrenInputsAreItsSignalsAndNoMirrorOutputIsLeft) {
  auto r = build_sim_machine(rt::parse_config_file(kDir + "drill-sim.yaml"));
  const auto& v = r->variables();
  for (const char* in : {"cnc.job.lin.start", "cnc.job.lin.lx_mm", "cnc.job.px.x_ref_mm",
                         "cnc.job.drill.depth_mm", "cnc.job.drill.tdr_us", "cnc.job.finish.start",
                         "cnc.job.manual.enable", "cnc.job.axes.cycle_z"}) {
    const rt::Variable* info = v.find(in);
    ASSERT_NE(info, nullptr) << in;
    EXPECT_EQ(info->kind, rt::VarKind::kInput) << in;
  }
  for (const char* out : {"cnc.job.axes.vz_cmd_mm_s", "cnc.job.axes.owner_z",
                          "cnc.job.probe.measured_depth_mm", "cnc.job.probe.step"}) {
    ASSERT_NE(v.find(out), nullptr) << out;
  }
  // The mirrors of before issue 32: each one was a cell that only crossed the job's boundary.
  for (const char* gone : {"cnc.job.lin_start", "cnc.job.x_ref_mm", "cnc.job.drill_start",
                           "cnc.job.feed_hold", "cnc.job.loop_enable", "cnc.job.vz_cmd_mm_s",
                           "cnc.job.finish.x_ref_mm", "cnc.job.finish.orbit_start",
                           "cnc.job.drill.vz_servo_cmd_mm_s", "cnc.job.drill.retract_enable"}) {
    EXPECT_EQ(v.find(gone), nullptr) << gone;
  }
}

TEST(EdmJobStructure, AWireIntoAnInputTheJobDrivesIsAnErrorAtTheWire) {
  std::string text = drill_sim_text();
  const std::string anchor = "    include: fragments/drill-job-wiring.yaml\n";
  const auto at = text.find(anchor);
  ASSERT_NE(at, std::string::npos);
  text.insert(at + anchor.size(), "    wires:\n      job.lin.start: true\n");
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n')) + 2;
  try {
    build_sim_machine(rt::parse_config_text(text, kDir + "drill-sim.yaml"));
    FAIL() << "a wire into job.lin.start was accepted";
  } catch (const rt::ConfigError& e) {
    const rt::Diagnostic& d = e.diagnostics().front();
    EXPECT_EQ(d.loc.line, line) << d.str();
    EXPECT_EQ(d.loc.col, 7) << d.str();
    EXPECT_NE(d.message.find("'job.lin.start' is driven by the program block that owns it"),
              std::string::npos)
        << d.str();
  }
}

}  // namespace
}  // namespace edm::test
