// EdmJob's depth probe (issue 20 f, docs/blocks.md "The depth probe") on the shipped drill
// machine: the sequence (rough drilling, bottom touch, surface touch beside the hole, finish from
// the contact, bottom touch again), what the machine does meanwhile (generator off and touch
// mode on while it touches, the surface touched where the parameters put it), the measured depth
// against the simulator's truth, a touch that finds nothing (the rest drilled on the estimate),
// and an operator stop and an E-stop in the middle of a touch.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "edm/hmi/gcode.hpp"
#include "edm/machining/machine_config.hpp"
#include "edm/runtime/variables.hpp"
#include "job_runner.hpp"

namespace edm::test {
namespace {

const std::string kMachine = std::string(EDM_SOURCE_DIR) + "/config/machines/drill-sim.yaml";

std::vector<machining::MotionBlock> blind_hole(double x, double y, double depth_mm) {
  char text[160];
  std::snprintf(text, sizeof text,
                "G17 G21 G90\nG00 X%.3f Y%.3f\nG00 Z0.5\nM03 M08\nE1\nG01 Z-%.3f F60\nE0\n"
                "G00 Z5.0\nM05 M09\nM30\n",
                x, y, depth_mm);
  hmi::GcodeOptions o;
  o.start_mm = {0, 0, 0.1};
  const auto g =
      hmi::interpret_gcode(text, "probe.nc", machining::read_machine_tables(kMachine), o);
  EXPECT_TRUE(g.ok()) << (g.ok() ? "" : g.messages()[0]);
  return g.blocks;
}

// What the machine did, step by step of the probe.
struct Seen {
  std::vector<std::int64_t> steps;  // probe_step values in the order they appeared
  int touches{0};                   // rising edges of the driver's touch mode
  bool gen_on_while_touching{false};
  bool gen_on_outside_drilling{false};
  double surface_x{0.0}, surface_y{0.0};  // where the axes stood during the surface touch
  double hole_x{0.0}, hole_y{0.0};        // and during the bottom touch
};

Seen watch(const rt::VariableRegistry& v, Seen& s, bool& touch_before) {
  const auto step = static_cast<std::int64_t>(v.read("cnc.job.probe.step").value());
  if (s.steps.empty() || s.steps.back() != step) s.steps.push_back(step);
  const bool touch = v.read("cnc.job.manual.touch_mode").value() != 0.0;
  if (touch && !touch_before) ++s.touches;
  touch_before = touch;
  const bool gen = v.read("io.gen_on").value() != 0.0;
  if (touch && gen) s.gen_on_while_touching = true;
  const bool drilling = step == 1 || step == 11;
  if (gen && !drilling && step != 0) s.gen_on_outside_drilling = true;
  if (touch && step == 7) {
    s.surface_x = v.read("io.x_mm").value();
    s.surface_y = v.read("io.y_mm").value();
  }
  if (touch && step == 3) {
    s.hole_x = v.read("io.x_mm").value();
    s.hole_y = v.read("io.y_mm").value();
  }
  return s;
}

TEST(DepthProbe, MeasuresBottomAndSurfaceThenFinishesFromTheContact) {
  // Off the origin, with the surface touched beside the hole in −Y: the probe's geometry follows
  // the hole and its parameters, not fixed coordinates.
  const double hx = 12.0, hy = -7.0, depth = 6.0;
  Seen s;
  bool touch_before = false;
  double measured = 0.0;
  std::int64_t failures = -1;
  const JobResult j = run_job(
      7, blind_hole(hx, hy, depth), {0, 0, 0.1}, kMachine,
      [&](const rt::VariableRegistry& v) {
        watch(v, s, touch_before);
        measured = v.read("cnc.job.probe.measured_depth_mm").value();
        failures = static_cast<std::int64_t>(v.read("cnc.job.probe.failures").value());
      },
      [](rt::Runtime& r) {
        ASSERT_TRUE(r.variables().write("cnc.job.probe.dx_mm", 0.0));
        ASSERT_TRUE(r.variables().write("cnc.job.probe.dy_mm", -3.0));
      });
  ASSERT_TRUE(j.finished);
  const std::vector<std::int64_t> expected = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 0};
  EXPECT_EQ(s.steps, expected);
  EXPECT_EQ(s.touches, 3) << "bottom, surface, bottom again";
  EXPECT_FALSE(s.gen_on_while_touching) << "touch mode senses with the generator off";
  EXPECT_FALSE(s.gen_on_outside_drilling);
  EXPECT_NEAR(s.hole_x, hx, 0.005);
  EXPECT_NEAR(s.hole_y, hy, 0.005);
  EXPECT_NEAR(s.surface_x, hx, 0.005);
  EXPECT_NEAR(s.surface_y, hy - 3.0, 0.005);
  EXPECT_EQ(failures, 0);
  // The measurement against the simulator's truth, and the hole against the program.
  EXPECT_NEAR(measured, j.depth_mm, 0.006);
  EXPECT_NEAR(j.depth_mm, depth, 0.010);
  EXPECT_NEAR(j.z_end_mm, 5.0, 0.005) << "the program's last move ends where it is programmed";
}

TEST(DepthProbe, SurfaceOffTheWorkFallsBackToTheEstimate) {
  // The surface touch point 60 mm beside the hole is off the 100 mm work block: that touch finds
  // no contact within manual.touch_max_mm. The probe counts a failure and the hole is drilled on
  // to its depth on eq. 8's estimate (as a resumed hole), nothing measured.
  Seen s;
  bool touch_before = false;
  double measured = -1.0;
  std::int64_t failures = -1;
  const JobResult j = run_job(
      3, blind_hole(0.0, 0.0, 4.0), {0, 0, 0.1}, kMachine,
      [&](const rt::VariableRegistry& v) {
        watch(v, s, touch_before);
        measured = v.read("cnc.job.probe.measured_depth_mm").value();
        failures = static_cast<std::int64_t>(v.read("cnc.job.probe.failures").value());
      },
      [](rt::Runtime& r) { ASSERT_TRUE(r.variables().write("cnc.job.probe.dx_mm", 60.0)); });
  ASSERT_TRUE(j.finished);
  EXPECT_EQ(failures, 1);
  EXPECT_EQ(measured, 0.0);
  const std::vector<std::int64_t> expected = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 0};
  EXPECT_EQ(s.steps, expected);
  EXPECT_EQ(s.touches, 2);
  EXPECT_FALSE(s.gen_on_while_touching);
  EXPECT_NEAR(j.depth_mm, 4.0, 0.030) << "the estimate's accuracy (docs/benchmarks.md)";
}

// Stops the machine (operator stop, or E-stop) in the middle of the bottom touch.
void stop_during_touch(rt::MachineCommand command, rt::MachineState after) {
  rt::BuildOptions opts;
  opts.seed = 11;
  auto r = build_sim_machine(rt::parse_config_file(kMachine), opts);
  ASSERT_EQ(r->job().load(blind_hole(0.0, 0.0, 2.0)), rt::LoadResult::kOk);
  r->machine().command(rt::MachineCommand::kPowerOn);
  ASSERT_EQ(r->machine().command(rt::MachineCommand::kStart), rt::CommandResult::kOk);
  auto& vars = r->variables();
  rt::VirtualClock clock;
  rt::Task& motion = *r->tasks()[0];
  rt::Task& supervisor = *r->tasks()[1];
  std::int64_t k = 0, stopped_at = -1;
  for (; k < 200'000; ++k) {
    const rt::TimePoint t{std::chrono::milliseconds(1) * k};
    clock.advance_to(t);
    motion.run_cycle(t, clock);
    if (k % 10 == 0) supervisor.run_cycle(t, clock);
    const bool touching = vars.read("cnc.job.manual.touch_mode").value() != 0.0;
    if (stopped_at < 0 && touching && vars.read("cnc.job.probe.step").value() == 3.0 &&
        vars.read("cnc.job.manual.vz_cmd_mm_s").value() < -0.5) {  // on the way down, fast
      r->machine().command(command, t);
      stopped_at = k;
    }
    if (stopped_at >= 0 && k >= stopped_at + 200) break;
  }
  ASSERT_GE(stopped_at, 0) << "the bottom touch never ran";
  EXPECT_EQ(r->machine().state(), after);
  EXPECT_EQ(r->job().progress().outcome, rt::JobOutcome::kAborted);
  EXPECT_EQ(vars.read("cnc.job.manual.touch_mode").value(), 0.0) << "touch mode ends";
  EXPECT_EQ(vars.read("cnc.job.manual.active").value(), 0.0) << "the touch gives the axes back";
  EXPECT_EQ(vars.read("cnc.job.probe.step").value(), 0.0);
  EXPECT_EQ(vars.read("io.gen_on").value(), 0.0);
  EXPECT_NEAR(vars.read("io.vz_cmd").value(), 0.0, 0.01) << "Z no longer moves down";
}

TEST(DepthProbe, AnOperatorStopDuringATouchEndsIt) {
  stop_during_touch(rt::MachineCommand::kStop, rt::MachineState::kReady);
}

TEST(DepthProbe, AnEStopDuringATouchEndsIt) {
  stop_during_touch(rt::MachineCommand::kEstop, rt::MachineState::kEstop);
}

}  // namespace
}  // namespace edm::test
