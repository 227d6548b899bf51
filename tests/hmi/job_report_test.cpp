// The job figures edmhmi reads from a status, the program's targets, durations and the job report
// (hmi/job_report.hpp).
#include "edm/hmi/job_report.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "edm/hmi/gcode.hpp"

namespace edm::hmi::test {
namespace {

using machining::MotionBlock;
using machining::MotionKind;

std::string printf_string(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

/// One report row as the operator reads it: label, at least two spaces, value, all labels
/// padded to one column.
std::string row(const std::string& label, const std::string& value) {
  return "  " + label + std::string(24 - label.size(), ' ') + value + "\n";
}

TEST(FiguresFromStatus, JobFiguresAreFoundByTheEndOfTheirName) {
  bridge::StatusMessage s;
  s.vars = {{"cnc.job.job_time_s", 57.25},
            {"cnc.job.job_pulses", 400000.0},
            {"other.prog.job_shorts", 9000},
            {"x.job_arcs", 1234.0},
            {"cnc.job.job_depth_mm", 15.004},
            {"cnc.job.job_wear_mm", 9.3},
            {"io.depth_mm", 14.998},
            {"io.electrode_mm", 190.7},
            {"io.wall_radius_mm", 0.6},
            {"io.x_mm", -20.0},
            {"io.y_mm", 10.0},
            {"io.z_mm", 5.0}};
  const JobFigures f = figures_from_status(s);
  EXPECT_EQ(f.time_s, 57.25);
  EXPECT_EQ(f.pulses, 400000.0);
  EXPECT_EQ(f.shorts, 9000.0);
  EXPECT_EQ(f.arcs, 1234.0);
  EXPECT_EQ(f.depth_mm, 15.004);
  EXPECT_EQ(f.wear_mm, 9.3);
  EXPECT_EQ(f.hole_depth_mm, 14.998);
  EXPECT_EQ(f.electrode_mm, 190.7);
  EXPECT_EQ(f.wall_radius_mm, 0.6);
  EXPECT_EQ(f.x_mm, -20.0);
  EXPECT_EQ(f.y_mm, 10.0);
  EXPECT_EQ(f.z_mm, 5.0);
  // The fractions are the counts' ratios.
  ASSERT_TRUE(f.short_fraction().has_value());
  ASSERT_TRUE(f.arc_fraction().has_value());
  EXPECT_DOUBLE_EQ(*f.short_fraction(), 9000.0 / 400000.0);
  EXPECT_DOUBLE_EQ(*f.arc_fraction(), 1234.0 / 400000.0);
}

TEST(FiguresFromStatus, OnlyTheWholeSuffixMatches) {
  bridge::StatusMessage s;
  // Not ".job_pulses" / not exactly "io.depth_mm": none of these is a figure.
  s.vars = {{"cnc.job.job_pulses_total", 1.0},
            {"cnc.jobjob_shorts", 2.0},
            {"job_arcs", 3.0},
            {"sim.io.depth_mm", 4.0},
            {"io.depth_mm.filtered", 5.0},
            {"io.x_mm2", 6.0},
            {"io.ratio_short", 0.1}};
  const JobFigures f = figures_from_status(s);
  EXPECT_FALSE(f.pulses);
  EXPECT_FALSE(f.shorts);
  EXPECT_FALSE(f.arcs);
  EXPECT_FALSE(f.hole_depth_mm);
  EXPECT_FALSE(f.x_mm);
  EXPECT_FALSE(f.short_fraction());
}

TEST(FiguresFromStatus, NonFiniteValuesAreAbsentAndFractionsNeedPulses) {
  bridge::StatusMessage s;
  s.vars = {{"a.job_pulses", 0.0},
            {"a.job_shorts", 5.0},
            {"a.job_arcs", 1.0},
            {"a.job_depth_mm", std::numeric_limits<double>::quiet_NaN()},
            {"io.z_mm", std::numeric_limits<double>::infinity()}};
  JobFigures f = figures_from_status(s);
  EXPECT_FALSE(f.depth_mm);
  EXPECT_FALSE(f.z_mm);
  EXPECT_FALSE(f.short_fraction()) << "no pulses: no fraction";
  EXPECT_FALSE(f.arc_fraction());
  f.pulses.reset();
  EXPECT_FALSE(f.short_fraction());
  f.pulses = 20.0;
  EXPECT_DOUBLE_EQ(*f.short_fraction(), 5.0 / 20.0);
  EXPECT_DOUBLE_EQ(*f.arc_fraction(), 1.0 / 20.0);
  f.arcs.reset();
  EXPECT_FALSE(f.arc_fraction());
}

TEST(ProgramTargets, DeepestDrillAndLargestOrbit) {
  std::vector<MotionBlock> blocks(7);
  blocks[0].kind = MotionKind::kRapid;
  blocks[0].target = {0, 0, -40};  // a rapid is not a drilling block
  blocks[1].kind = MotionKind::kDrill;
  blocks[1].target = {0, 0, -15};
  blocks[2].kind = MotionKind::kDrill;
  blocks[2].target = {5, 0, -20.5};
  blocks[3].kind = MotionKind::kOrbitFinish;
  blocks[3].final_radius_mm = 0.6;
  blocks[4].kind = MotionKind::kOrbitFinish;
  blocks[4].final_radius_mm = 0.45;
  blocks[5].kind = MotionKind::kLinear;
  blocks[5].target = {0, 0, -30};
  blocks[6].kind = MotionKind::kEnd;
  const ProgramTargets t = program_targets(blocks);
  EXPECT_EQ(t.blocks, 7u);
  EXPECT_DOUBLE_EQ(t.deepest_drill_mm, 20.5);
  EXPECT_DOUBLE_EQ(t.largest_radius_mm, 0.6);

  const ProgramTargets none = program_targets({});
  EXPECT_EQ(none.blocks, 0u);
  EXPECT_EQ(none.deepest_drill_mm, 0.0);
  EXPECT_EQ(none.largest_radius_mm, 0.0);
}

TEST(FormatDuration, MinutesSecondsAndHours) {
  EXPECT_EQ(format_duration(0.0), "0:00");
  EXPECT_EQ(format_duration(59.4), "0:59");
  EXPECT_EQ(format_duration(59.6), "1:00");
  EXPECT_EQ(format_duration(62.0), "1:02");
  EXPECT_EQ(format_duration(3599.0), "59:59");
  EXPECT_EQ(format_duration(3600.0), "1:00:00");
  EXPECT_EQ(format_duration(3723.0), "1:02:03");
  EXPECT_EQ(format_duration(36000.0 + 59.0), "10:00:59");
  EXPECT_EQ(format_duration(-1.0), "--:--");
  EXPECT_EQ(format_duration(std::numeric_limits<double>::quiet_NaN()), "--:--");
  EXPECT_EQ(format_duration(std::numeric_limits<double>::infinity()), "--:--");
}

JobReport sample_report() {
  JobReport r;
  r.part = "hole.nc";
  r.machine = "drill-sim";
  r.outcome = "finished";
  r.state = "READY";
  r.targets.blocks = 12;
  r.targets.deepest_drill_mm = 15.0;
  r.targets.largest_radius_mm = 0.6;
  r.blocks_done = 12;
  r.end.time_s = 57.3;
  r.end.depth_mm = 14.9876;
  r.end.hole_depth_mm = 14.9912;
  r.end.wall_radius_mm = 0.5987;
  r.end.wear_mm = 9.284;
  r.end.electrode_mm = 190.5;
  r.electrode_at_start_mm = 200.0;
  r.end.pulses = 123456.0;
  r.end.shorts = 2345.0;
  r.end.arcs = 67.0;
  return r;
}

TEST(FormatReport, ShowsTheDepthErrorAndFractionsFromTheNumbers) {
  const JobReport r = sample_report();
  const std::string text = format_report(r);
  EXPECT_NE(text.find("job report: hole.nc on drill-sim\n"), std::string::npos) << text;
  EXPECT_NE(text.find(row("outcome", "finished")), std::string::npos) << text;
  EXPECT_NE(text.find(row("blocks", "12 of 12")), std::string::npos) << text;
  EXPECT_NE(text.find(row("machining time", "0:57 (57.3 s)")), std::string::npos) << text;
  const double error = *r.end.depth_mm - r.targets.deepest_drill_mm;  // -0.0124
  const std::string depth_row =
      row("depth reached", printf_string("%.4f mm", *r.end.depth_mm) + " (program " +
                               printf_string("%.4f mm", r.targets.deepest_drill_mm) + ", error " +
                               printf_string("%+.4f mm", error) + ")");
  EXPECT_EQ(depth_row, row("depth reached", "14.9876 mm (program 15.0000 mm, error -0.0124 mm)"));
  EXPECT_NE(text.find(depth_row), std::string::npos) << text;
  EXPECT_NE(text.find(row("hole depth (measured)", "14.9912 mm")), std::string::npos) << text;
  EXPECT_NE(text.find(row("wall radius (measured)", "0.5987 mm (program 0.6000 mm)")),
            std::string::npos)
      << text;
  const double used = *r.electrode_at_start_mm - *r.end.electrode_mm;
  EXPECT_NE(text.find(row("electrode used", "9.284 mm estimated (eq. 8), " +
                                                printf_string("%.3f", used) + " mm measured")),
            std::string::npos)
      << text;
  EXPECT_NE(text.find(row("pulses", "123456")), std::string::npos) << text;
  const std::string shorts = printf_string("%.2f %%", 100.0 * 2345.0 / 123456.0);
  const std::string arcs = printf_string("%.2f %%", 100.0 * 67.0 / 123456.0);
  EXPECT_NE(text.find(row("short circuits", shorts)), std::string::npos) << text;
  EXPECT_NE(text.find(row("arcs", arcs)), std::string::npos) << text;
  EXPECT_NE(text.find(row("alarms", "none")), std::string::npos) << text;
}

// A dry run moves without drilling: its report says so and reports no depth error (issue 33: it
// read "error -12.0000 mm").
TEST(FormatReport, ADryRunIsLabelledAndHasNoDepthError) {
  JobReport r = sample_report();
  r.dry_run = true;
  r.end.depth_mm = 0.0;
  const std::string text = format_report(r);
  EXPECT_NE(text.find(row("outcome", "finished (dry run)")), std::string::npos) << text;
  EXPECT_NE(text.find(row("depth reached", "not drilled: a dry run (program 15.0000 mm)")),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("error"), std::string::npos) << text;
}

// `edmhmi status` knows the machine's last cause, not the job's alarms: it must not print
// "FAULT (alarm 110)" and then "alarms none" (issue 33).
TEST(FormatReport, AReportWhoseAlarmsWereNotWatchedClaimsNone) {
  JobReport r = sample_report();
  r.outcome = "aborted";
  r.state = "FAULT";
  r.cause = 110;
  r.alarms_seen = false;
  const std::string text = format_report(r);
  EXPECT_NE(text.find(row("outcome", "aborted (machine FAULT, alarm 110)")), std::string::npos)
      << text;
  EXPECT_EQ(text.find("alarms"), std::string::npos) << text;
}

TEST(FormatReport, AbortedJobShowsCauseAlarmsAndMissingFigures) {
  JobReport r = sample_report();
  r.outcome = "aborted";
  r.state = "FAULT";
  r.cause = 141;
  r.blocks_done = 5;
  r.end = {};
  r.end.depth_mm = 7.5;
  r.alarms = {"141 soft_limit (fault, cnc.job): Z beyond -60", "210 watchdog (warn, motion): x"};
  const std::string text = format_report(r);
  EXPECT_NE(text.find(row("outcome", "aborted (machine FAULT, alarm 141)")), std::string::npos)
      << text;
  EXPECT_NE(text.find(row("blocks", "5 of 12")), std::string::npos) << text;
  EXPECT_NE(text.find("error " + printf_string("%+.4f", 7.5 - 15.0) + " mm"), std::string::npos)
      << text;
  EXPECT_NE(text.find(row("machining time", "n/a")), std::string::npos) << text;
  EXPECT_NE(text.find(row("short circuits", "n/a")), std::string::npos) << text;
  EXPECT_EQ(text.find("hole depth (measured)"), std::string::npos) << text;
  EXPECT_NE(text.find(row("alarms", "2") + "    141 soft_limit (fault, cnc.job): Z beyond "
                                           "-60\n    210 watchdog (warn, motion): x\n"),
            std::string::npos)
      << text;
}

TEST(FormatReport, NoDrillingNoDepthRow) {
  JobReport r = sample_report();
  r.targets.deepest_drill_mm = 0.0;
  r.targets.largest_radius_mm = 0.0;
  r.end.depth_mm = 0.0;
  const std::string text = format_report(r);
  EXPECT_EQ(text.find("depth reached"), std::string::npos) << text;
  EXPECT_EQ(text.find("hole depth"), std::string::npos) << text;
  EXPECT_EQ(text.find("wall radius"), std::string::npos) << text;
}

TEST(FormatReport, UnknownProgramStillShowsTheDepthTheMachineReached) {
  // `edmhmi status` knows the job's figures, not its program.
  JobReport r = sample_report();
  r.targets = {};
  r.targets.blocks = 12;
  const std::string text = format_report(r);
  EXPECT_NE(text.find(row("depth reached", "14.9876 mm")), std::string::npos) << text;
  EXPECT_NE(text.find(row("hole depth (measured)", "14.9912 mm")), std::string::npos) << text;
  EXPECT_EQ(text.find("program 15"), std::string::npos) << text;
  EXPECT_EQ(text.find("error"), std::string::npos) << text;
}

TEST(FormatProgress, DrillingBarFollowsTheDepth) {
  ProgressView v;
  v.state = "RUNNING";
  v.block = 5;
  v.blocks = 14;
  v.line = 10;
  v.kind = MotionKind::kDrill;
  v.drill_target_mm = 15.0;
  v.figures.depth_mm = 7.5;
  v.elapsed_s = 20.0;
  v.eta_s = 20.0;
  const std::string line = format_progress(v, 10);
  EXPECT_EQ(
      line.rfind("[#####.....]  50% depth   7.500 / 15.000 mm  block 6/14 (line 10 drill)", 0), 0u)
      << line;
  EXPECT_NE(line.find("0:20 elapsed  ETA 0:20  RUNNING"), std::string::npos) << line;
}

TEST(FormatProgress, BlockBarAndAFinishedJobAtHundredPercent) {
  ProgressView v;
  v.state = "RUNNING";
  v.outcome = "running";
  v.block = 7;
  v.blocks = 14;
  v.line = 12;
  v.kind = MotionKind::kRapid;
  v.elapsed_s = 42.0;
  v.eta_s = 42.0;
  const std::string half = format_progress(v, 10);
  EXPECT_EQ(half.rfind("[#####.....]  50% block 8/14 (line 12 rapid)  0:42 elapsed  ETA 0:42", 0),
            0u)
      << half;
  // The last status of a finished job sits on its end block (index N-1): the bar is full.
  v.state = "READY";
  v.outcome = "finished";
  v.block = 13;
  v.kind = MotionKind::kEnd;
  v.eta_s = 3.0;
  const std::string done = format_progress(v, 10);
  EXPECT_EQ(done.rfind("[##########] 100% block 14/14", 0), 0u) << done;
  EXPECT_NE(done.find("ETA 0:00  READY"), std::string::npos) << done;
}

// A hole drilled in G55, whose origin is at machine (-30, 40, -35): the report names the frame
// and gives the hole and the end position in both coordinate systems.
TEST(FormatReport, PositionsInWorkAndMachineCoordinates) {
  machining::MachineTables tables;
  tables.conditions.push_back({.e = 1, .name = "drill", .wear_ratio = 0.5});
  GcodeOptions o;
  o.offsets.frame[1] = {-30.0, 40.0, -35.0};
  o.start_mm = {0.0, 0.0, 10.0};
  const GcodeResult g = interpret_gcode(
      "G55\nG00 X2 Y-1 Z5\nG00 Z0.5\nE1\nG01 Z-4 F60\nE0\nG00 Z5\nM30\n", "h.nc", tables, o);
  ASSERT_TRUE(g.ok());
  JobReport r = sample_report();
  r.targets = program_targets(g.blocks, g.frames);
  ASSERT_EQ(r.targets.holes.size(), 1u);
  EXPECT_EQ(r.targets.holes[0].line, 5);
  EXPECT_EQ(r.targets.holes[0].machine_mm, (machining::Vec3{-28.0, 39.0, -39.0}));
  EXPECT_EQ(r.targets.holes[0].work_mm, (machining::Vec3{2.0, -1.0, -4.0}));
  EXPECT_DOUBLE_EQ(r.targets.deepest_drill_mm, 4.0);  // from G55's Z0, not machine Z 0
  r.end.x_mm = -28.0;
  r.end.y_mm = 39.0;
  r.end.z_mm = -30.0;
  const std::string text = format_report(r);
  EXPECT_NE(text.find(row("work frame", "G55, origin at X -30.0000 Y 40.0000 Z -35.0000 machine")),
            std::string::npos)
      << text;
  EXPECT_NE(text.find(row("hole (line 5)",
                          "X 2.0000 Y -1.0000 G55 = X -28.0000 Y 39.0000 "
                          "machine, 4.0000 mm deep")),
            std::string::npos)
      << text;
  EXPECT_NE(text.find(row("end position",
                          "X 2.0000 Y -1.0000 Z 5.0000 G55 = X -28.0000 Y "
                          "39.0000 Z -30.0000 machine")),
            std::string::npos)
      << text;
}

TEST(FormatReport, G92IsNamedAndManyHolesAreCut) {
  machining::MachineTables tables;
  tables.conditions.push_back({.e = 1, .name = "drill", .wear_ratio = 0.5});
  std::string text = "G00 Z1\nG92 Z0.5\nE1\n";
  for (int i = 0; i < 12; ++i) text += "G00 X" + std::to_string(i) + "\nG01 Z-1 F60\n";
  text += "M30\n";
  const GcodeResult g = interpret_gcode(text, "row.nc", tables);
  ASSERT_TRUE(g.ok());
  JobReport r = sample_report();
  r.targets = program_targets(g.blocks, g.frames);
  EXPECT_EQ(r.targets.holes.size(), 12u);
  r.end = {};  // no position: no end row
  const std::string out = format_report(r);
  EXPECT_NE(out.find(row("work frame", "G54 + G92, origin at X 0.0000 Y 0.0000 Z 0.5000 machine")),
            std::string::npos)
      << out;
  EXPECT_NE(out.find(row("", "... and 2 more holes")), std::string::npos) << out;
  EXPECT_EQ(out.find("end position"), std::string::npos) << out;
}

TEST(FormatReport, WithoutTheProgramOnlyTheMachinePosition) {
  JobReport r = sample_report();
  r.end.x_mm = 1.0;
  r.end.y_mm = 2.0;
  r.end.z_mm = 3.0;
  const std::string text = format_report(r);
  EXPECT_NE(text.find(row("end position", "X 1.0000 Y 2.0000 Z 3.0000 machine")), std::string::npos)
      << text;
  EXPECT_EQ(text.find("work frame"), std::string::npos) << text;
}

TEST(ProgramTargets, DepthComesFromDepthMmOrTheOldMachineZ0) {
  MotionBlock d{};
  d.kind = MotionKind::kDrill;
  d.target = {0, 0, -30.0};
  EXPECT_DOUBLE_EQ(drill_depth_of(d), 30.0);  // no depth_mm: machine Z 0 is the surface
  d.depth_mm = 6.0;
  EXPECT_DOUBLE_EQ(drill_depth_of(d), 6.0);
  EXPECT_DOUBLE_EQ(program_targets({d}).deepest_drill_mm, 6.0);
  // Frames of the wrong size are ignored, not misread.
  EXPECT_TRUE(program_targets({d}, {}).holes.empty());
  EXPECT_FALSE(program_targets({d}, {}).end_frame.has_value());
}

}  // namespace
}  // namespace edm::hmi::test
