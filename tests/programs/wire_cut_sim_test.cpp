// The wire machine cutting a part (issue 34): examples/parts/wire-punch.nc on wire-sim, the
// punch measured from the simulator's truth after each pass.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
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

TEST(WirePunch, TheSquarePunchIsTenMillimetresAfterTheLastSkim) {
  const auto [lo, hi] = seeds(1, 5);
  for (int seed = lo; seed <= hi; ++seed) {
    WireRun run(seed, punch_program());
    const bool verbose = std::getenv("EDM_WIRE_VERBOSE") != nullptr;
    run.run(3600.0, [&](WireRun& r) {
      if (verbose && r.k % 2000 == 0) {
        std::printf("t %.0f line %.0f x %.4f y %.4f v %.4f back %.4f U %.1f gap %.1f "
                    "c %.3f ck %.3f sh %.0f no %.0f arc %.0f op %.0f\n",
                    static_cast<double>(r.k) * 1e-3, r.read("cnc.job.line"), r.read("io.x_mm"),
                    r.read("io.y_mm"), r.read("cnc.job.wire.path_speed_mm_s"),
                    r.read("cnc.job.wire.back_mm"), r.read("io.gap_voltage_v"),
                    r.read("io.true_gap_um"), r.read("io.true_debris"),
                    r.read("io.true_kerf_debris"), r.read("io.n_short"), r.read("io.n_normal"),
                    r.read("io.n_transient_arc") + r.read("io.n_stable_arc"), r.read("io.n_open"));
      }
    });
    ASSERT_TRUE(run.finished) << "seed " << seed << " at " << run.k << " ms, state "
                              << static_cast<int>(run.runtime->machine().state());
    const PunchSize s = measure_punch(run.plant().wire_plane(), 0.0, 0.0);
    std::printf("seed %d: punch %.4f x %.4f mm, corner %.4f mm (ideal %.4f), %.1f s\n", seed,
                s.x_mm, s.y_mm, s.corner_mm, 5.0 * std::sqrt(2.0),
                static_cast<double>(run.k) * 1e-3);
    EXPECT_NEAR(s.x_mm, 10.0, 0.005) << "seed " << seed;
    EXPECT_NEAR(s.y_mm, 10.0, 0.005) << "seed " << seed;
  }
}

}  // namespace
}  // namespace edm::test
