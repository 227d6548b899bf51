// Seed 003: the quantised table against direct Mamdani inference at OFF-grid inputs.
//
// The table is only defined at integer counts. A continuous input x = (x_o, x_s) (the expected
// open and short counts of a 32-pulse window, 0 ≤ x_o + x_s ≤ 32) is read the way a counter would
// give it, at the nearest counts g = (round x_o, round x_s), and compared with direct inference
// F(x) by an engine built here from the parameter text (not the block's instance).
//
// Bound, derived:  |T(g) − F(x)| ≤ |T(g) − F(g)| + |F(g) − F(x)| ≤ lsb/2 + V(cell)
//   - lsb/2: the paper's coding rounds to the nearest code, one code = lsb = 366/(30000·5) of
//     full scale, and decoding is exact, so |T(g) − F(g)| ≤ lsb/2 (F ∈ [−1, 1]: no clamping).
//   - V(cell): g is a corner of the unit cell C ∋ x. If F is monotone in each input on C, F(x)
//     lies between the smallest and the largest corner value, so |F(g) − F(x)| ≤ V(cell) =
//     max over C's corners of F − min over C's corners of F (the inference's variation between
//     grid points). Monotonicity on C is not assumed: the test fails if F leaves the corners'
//     range inside a cell.
// The test therefore checks the quantisation and that the surface has no bump between grid
// points that the table cannot see; it never compares the table with the values that filled it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "blocks/block_harness.hpp"
#include "edm/blocks/fuzzy_mamdani.hpp"
#include "edm/blocks/fuzzy_servo_lut.hpp"
#include "fuzzy_variables.hpp"

namespace edm::blocks {
namespace {

using test::variable;

fuzzy::MamdaniEngine engine_from(const FuzzyServoLUTParams& p) {
  std::vector<fuzzy::Variable> in{
      variable("open", p.open_terms), variable("short", p.short_terms), {"normal", {}}};
  fuzzy::Variable out = variable("v", p.velocity_terms);
  fuzzy::SyntaxError err;
  auto rules = fuzzy::parse_rules(p.rules, in, out, err);
  EXPECT_TRUE(rules.has_value()) << err.message;
  return fuzzy::MamdaniEngine(in, out, rules.value_or(std::vector<fuzzy::Rule>{}),
                              static_cast<std::size_t>(p.samples));
}

double infer(const fuzzy::MamdaniEngine& e, double o, double s) {
  const double x[3] = {o, s, std::max(0.0, 32.0 - o - s)};
  return e.infer(x);
}

struct Figures {
  double max_err{0.0};    // max |T(g) − F(x)|
  double max_bound{0.0};  // max lsb/2 + V(cell)
  double max_slack_used{0.0};
  double half_code{0.0};
};

Figures check_off_grid(const FuzzyServoLUTParams& p, std::uint64_t seed, int points) {
  Figures f;
  BlockHarness<FuzzyServoLUT> h;
  h.start_ok(p);
  auto& open = h.source<std::int64_t>("open_count");
  auto& shorts = h.source<std::int64_t>("short_count");
  const auto eng = engine_from(p);
  const double half_code = h.block().lsb() / 2.0;
  f.half_code = half_code;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 32.0);
  int checked = 0;
  while (checked < points) {
    const double xo = u(rng);
    const double xs = u(rng);
    if (xo + xs > 32.0) {
      continue;  // the reachable triangle
    }
    const double fx = infer(eng, xo, xs);
    EXPECT_FALSE(std::isnan(fx)) << xo << "," << xs;
    const auto go = static_cast<std::int64_t>(std::lround(xo));
    const auto gs = static_cast<std::int64_t>(std::lround(xs));
    open.set(go);
    shorts.set(gs);
    EXPECT_EQ(h.step(), BlockStatus::kOk);
    const double table = h.out("v_mm_s") / p.v_max_mm_s;
    // The unit cell holding x, and F's range over its corners.
    const double o0 = std::floor(xo);
    const double s0 = std::floor(xs);
    double lo = 1e9;
    double hi = -1e9;
    for (const double co : {o0, std::min(o0 + 1.0, 32.0)}) {
      for (const double cs : {s0, std::min(s0 + 1.0, 32.0)}) {
        const double fc = infer(eng, co, cs);
        lo = std::min(lo, fc);
        hi = std::max(hi, fc);
      }
    }
    const double bound = half_code + (hi - lo) + 1e-12;
    const double err = std::abs(table - fx);
    EXPECT_LE(err, bound) << "x = (" << xo << ", " << xs << "), counts (" << go << ", " << gs
                          << "): table " << table << ", F(x) " << fx << ", corners [" << lo << ", "
                          << hi << "]";
    f.max_err = std::max(f.max_err, err);
    f.max_bound = std::max(f.max_bound, bound);
    f.max_slack_used = std::max(f.max_slack_used, err / bound);
    ++checked;
  }
  return f;
}

TEST(Seed003LutVsInference, default_surface_within_half_a_code_plus_the_cell_variation) {
  const Figures f = check_off_grid(FuzzyServoLUTParams{}, 3003, 20000);
  // The figures quoted in docs/controllers.md (normalised units, 1 = v_max).
  RecordProperty("max_abs_error", std::to_string(f.max_err));
  RecordProperty("max_bound", std::to_string(f.max_bound));
  std::printf("default surface: max |T(g) - F(x)| = %.5f, largest bound %.5f, max err/bound %.3f\n",
              f.max_err, f.max_bound, f.max_slack_used);
  // The comparison is not vacuous: off-grid reads miss F by more than the quantisation alone.
  EXPECT_GT(f.max_err, f.half_code);
}

TEST(Seed003LutVsInference, a_coarser_rule_base_with_three_output_terms) {
  // The wire program's rule base (tests/data/alloc/seed_003_000.yaml): 3 output terms, rules on
  // one input only; its surface has plateaus and steep ramps.
  FuzzyServoLUTParams p;
  p.velocity_terms = "NB=tri(-1.5,-1,-0.5) ZE=tri(-0.5,0,0.5) PB=tri(0.5,1,1.5)";
  p.rules =
      "if open is Z and short is Z then v is ZE; if open is M and short is Z then v is PB; "
      "if open is L then v is PB; if short is M then v is NB; if short is L then v is NB";
  const Figures f = check_off_grid(p, 3004, 20000);
  std::printf("coarse surface: max |T(g) - F(x)| = %.5f, largest bound %.5f, max err/bound %.3f\n",
              f.max_err, f.max_bound, f.max_slack_used);
}

}  // namespace
}  // namespace edm::blocks
