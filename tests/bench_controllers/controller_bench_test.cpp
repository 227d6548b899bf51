// The controller benchmark's runner (apps/bench/controllers): B7 determinism on short runs, and
// a controller property the benchmark measures.

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <string>

#include "controllers/bench.hpp"

namespace edm::bench {
namespace {

const std::string kRoot = EDM_SOURCE_DIR;

// The scenario's variant by name (fails the test if the scenario list changed).
RunSpec spec_of(const std::string& id, std::size_t variant, bool quick = true) {
  for (const Scenario& s : make_scenarios(quick)) {
    if (s.id == id && variant < s.variants.size()) {
      return s.variants[variant].spec;
    }
  }
  ADD_FAILURE() << "no scenario " << id << " variant " << variant;
  return {};
}

void expect_bitwise_equal(const Outcome& a, const Outcome& b) {
  const auto fa = a.fields();
  const auto fb = b.fields();
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t i = 0; i < fa.size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(fa[i].second),
              std::bit_cast<std::uint64_t>(fb[i].second))
        << fa[i].first << ": " << fa[i].second << " vs " << fb[i].second;
  }
  EXPECT_EQ(a.jitter_per_cycle_um, b.jitter_per_cycle_um);
}

TEST(ControllerBench, B7SameSeedGivesIdenticalFiguresAnotherSeedDoesNot) {
  for (const auto& [id, variant] :
       {std::pair<std::string, std::size_t>{"B1", 0}, {"B5", 1}, {"B6a", 1}}) {
    SCOPED_TRACE(id);
    RunSpec spec = spec_of(id, variant);
    spec.limit_s = 4.0;
    spec.seed = 11;
    const Outcome a = run(kRoot, spec);
    const Outcome b = run(kRoot, spec);
    expect_bitwise_equal(a, b);
    EXPECT_GT(a.depth_mm, 0.0) << "the run machined something";
    spec.seed = 12;
    const Outcome c = run(kRoot, spec);
    EXPECT_NE(a.depth_mm, c.depth_mm) << "another seed, other noise";
  }
}

}  // namespace
}  // namespace edm::bench
