// The wire machine cutting a part (issue 34): examples/parts/wire-punch.nc on wire-sim, the
// punch measured from the simulator's truth after each pass.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <chrono>
#include <string>

#include "wire_rig.hpp"

namespace edm::test {
namespace {

std::string punch_program() {
  return read_text(std::string(EDM_SOURCE_DIR) + "/examples/parts/wire-punch.nc");
}

// EDM_WIRE_SEEDS=1000-1004 prints the calibration (the offsets of wire-sim.yaml's conditions).
std::pair<int, int> seeds(int lo, int hi) {
  if (const char* s = std::getenv("EDM_WIRE_SEEDS")) {
    int a = lo, b = hi;
    if (std::sscanf(s, "%d-%d", &a, &b) == 2) return {a, b};
  }
  return {lo, hi};
}

void print(const char* what, int seed, const PunchSize& s) {
  // The corner's error: its distance from the centre along the diagonal less a sharp corner's
  // for the punch's own size (negative: rounded off).
  const double half = (s.x_min + s.x_max + s.y_min + s.y_max) / 8.0;
  std::printf("seed %d %s: X %.4f..%.4f Y %.4f..%.4f mm, corner %+.4f mm\n", seed, what, s.x_min,
              s.x_max, s.y_min, s.y_max, s.corner_mm - half * std::sqrt(2.0));
}

TEST(WirePunch, TheSquarePunchIsTenMillimetresAfterTheLastSkim) {
  const auto [lo, hi] = seeds(1, 5);
  for (int seed = lo; seed <= hi; ++seed) {
    WireRun run(seed, punch_program());
    const bool verbose = std::getenv("EDM_WIRE_VERBOSE") != nullptr;
    double line = 0.0;
    run.run(3600.0 * 3, [&](WireRun& r) {
      const double now = r.read("cnc.job.line");
      if (now != line && (now == 10.0 || now == 11.0)) {  // a skim begins: the pass before
        print(now == 10.0 ? "main cut" : "skim 1", seed, measure_punch(r.plant().wire_plane(), 0, 0));
      }
      line = now;
      if (verbose && r.k % 5000 == 0) {
        std::printf("t %.0f line %.0f x %.4f y %.4f v %.4f back %.4f U %.1f gap %.1f\n",
                    static_cast<double>(r.k) * 1e-3, now, r.read("io.x_mm"), r.read("io.y_mm"),
                    r.read("cnc.job.wire.path_speed_mm_s"), r.read("cnc.job.wire.back_mm"),
                    r.read("io.gap_voltage_v"), r.read("io.true_gap_um"));
      }
    });
    ASSERT_TRUE(run.finished) << "seed " << seed << " " << run.where();
    const PunchSize s = measure_punch(run.plant().wire_plane(), 0.0, 0.0);
    print("skim 2", seed, s);
    std::printf("seed %d: %.1f s\n", seed, static_cast<double>(run.k) * 1e-3);
    for (double w : {s.x_min, s.x_max, s.y_min, s.y_max}) EXPECT_NEAR(w, 10.0, 0.005) << seed;
  }
}

// A contact just past the punch's first corner (seed 6): the wire backs along the path it cut,
// back across the corner onto the left edge, never forward while the gap reads short, then cuts
// on; the punch still ends within ±5 µm.
TEST(WireCut, AContactBacksTheWireAlongThePathAcrossACornerNeverForwardWhileShort) {
  WireRun run(6, punch_program());
  bool injected = false;
  std::int64_t inject_k = 0, forward_while_short = 0, short_cycles = 0;
  double y_min_after = 1e9, x_off_path = 0.0;
  run.run(3600.0 * 3, [&](WireRun& r) {
    const double x = r.read("io.x_mm"), y = r.read("io.y_mm");
    // On the top edge's offset (y 5.2), 20 µm past the corner arc's end (x −5), in the main cut.
    if (!injected && r.read("cnc.job.line") == 18.0 && y > 5.19 && x > -4.98) {
      r.plant().inject_short(std::chrono::seconds(4));
      injected = true;
      inject_k = r.k;
    }
    if (r.read("cnc.job.wire.shorted") != 0.0) {
      ++short_cycles;
      if (r.read("cnc.job.wire.path_speed_mm_s") > 0.0) ++forward_while_short;
    }
    if (injected && r.k < inject_k + 6000) {
      y_min_after = std::min(y_min_after, y);
      // Back on the left edge (below the arc), the wire is on the path it cut: x = −5.2.
      if (y < 4.99) x_off_path = std::max(x_off_path, std::fabs(x + 5.2));
    }
  });
  ASSERT_TRUE(injected);
  ASSERT_TRUE(run.finished) << run.where();
  EXPECT_GT(short_cycles, 1000) << "the contact held the gap short";
  EXPECT_EQ(forward_while_short, 0);
  EXPECT_LT(y_min_after, 4.95) << "backed across the corner arc onto the left edge";
  EXPECT_LT(x_off_path, 0.003) << "along the path";
  EXPECT_GT(run.read("cnc.job.wire.shorts"), 0.0);
  const PunchSize s = measure_punch(run.plant().wire_plane(), 0.0, 0.0);
  print("after a contact", 6, s);
  for (double w : {s.x_min, s.x_max, s.y_min, s.y_max}) EXPECT_NEAR(w, 10.0, 0.005);
}

// A wire break mid-cut: alarm 170, the safe state (generator off, the axes stopped), the job
// aborted where it broke.
TEST(WireCut, AWireBreakMidCutIsTheSafeStateWithAlarm170) {
  WireRun run(7, punch_program());
  bool broke = false;
  double line_at_break = 0.0;
  run.run(600.0, [&](WireRun& r) {
    if (!broke && r.read("cnc.job.line") == 17.0 && r.read("io.y_mm") > 2.0) {
      r.plant().break_wire();
      broke = true;
      line_at_break = r.read("cnc.job.line");
    }
  });
  ASSERT_TRUE(broke);
  EXPECT_FALSE(run.finished);
  EXPECT_EQ(run.runtime->machine().state(), rt::MachineState::kFault);
  EXPECT_EQ(static_cast<int>(run.runtime->machine().last_cause()), 170);
  EXPECT_EQ(line_at_break, 17.0);
  EXPECT_EQ(run.read("io.gen_on"), 0.0);
  EXPECT_EQ(run.read("io.vx_cmd"), 0.0);
  EXPECT_EQ(run.read("io.vy_cmd"), 0.0);
  EXPECT_EQ(run.runtime->job().progress().outcome, rt::JobOutcome::kAborted);
}

}  // namespace
}  // namespace edm::test
