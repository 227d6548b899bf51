#include "edm/blocks/orbit_expander.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "block_harness.hpp"

namespace edm::blocks {
namespace {

struct Rig {
  explicit Rig(OrbitExpanderParams p = {}) {
    h.start_ok(p);
    enable.set(true);
  }
  BlockStatus start_orbit(double r0_mm, double final_mm) {
    r0.set(r0_mm);
    fin.set(final_mm);
    return h.rising_edge("start");
  }
  /// One sample of a revolution; the last one with the rev_pulse edge.
  BlockStatus sample(double td, bool ok = true, bool last = false) {
    td_us.set(td);
    valid.set(ok);
    rev.set(last);
    const BlockStatus s = h.step();
    rev.set(false);
    return s;
  }
  /// A revolution of the given samples (all valid); returns the status of the closing sample.
  BlockStatus revolution(const std::vector<double>& tds) {
    for (std::size_t k = 0; k + 1 < tds.size(); ++k) {
      EXPECT_EQ(sample(tds[k]), BlockStatus::kOk);
    }
    return sample(tds.back(), true, true);
  }
  [[nodiscard]] double radius() const { return h.out("radius_mm"); }
  [[nodiscard]] double dr() const { return h.out("dr_mm"); }
  [[nodiscard]] double tdm() const { return h.out("tdm_us"); }
  [[nodiscard]] std::int64_t revs() const { return h.out<std::int64_t>("revolutions"); }
  [[nodiscard]] bool busy() const { return h.out<bool>("busy"); }
  [[nodiscard]] bool done() const { return h.out<bool>("done"); }

  BlockHarness<OrbitExpander> h{1ms};
  rt::Output<bool>& start = h.source<bool>("start");
  rt::Output<double>& r0 = h.source<double>("r0_mm");
  rt::Output<double>& fin = h.source<double>("final_radius_mm");
  rt::Output<bool>& enable = h.source<bool>("enable");
  rt::Output<double>& td_us = h.source<double>("td_us");
  rt::Output<bool>& valid = h.source<bool>("valid");
  rt::Output<bool>& rev = h.source<bool>("rev_pulse");
};

TEST(OrbitExpanderTest, grows_by_kr_times_the_mean_td_each_revolution) {
  // kr = 2^-10 mm/µs; Td values whose means are exact in binary.
  Rig r({.kr = 1.0 / 1024.0, .dr_max_mm = 1.0, .samples_per_rev = 0});
  ASSERT_EQ(r.start_orbit(0.5, 10.0), BlockStatus::kOk);
  EXPECT_TRUE(r.busy());
  EXPECT_EQ(r.radius(), 0.5);
  EXPECT_EQ(r.revs(), 0);
  EXPECT_EQ(r.revolution({10.0, 20.0, 30.0, 40.0}), BlockStatus::kOk);  // Tdm = 25
  EXPECT_EQ(r.tdm(), 25.0);
  EXPECT_EQ(r.dr(), 25.0 / 1024.0);
  EXPECT_EQ(r.radius(), 0.5 + 25.0 / 1024.0);
  EXPECT_EQ(r.revs(), 1);
  EXPECT_EQ(r.revolution({8.0, 8.0}), BlockStatus::kOk);  // Tdm = 8
  EXPECT_EQ(r.tdm(), 8.0);
  EXPECT_EQ(r.dr(), 8.0 / 1024.0);
  EXPECT_EQ(r.radius(), 0.5 + 25.0 / 1024.0 + 8.0 / 1024.0);
  EXPECT_EQ(r.revs(), 2);
  // Between revolution ends, the radius and dr hold.
  EXPECT_EQ(r.sample(100.0), BlockStatus::kOk);
  EXPECT_EQ(r.radius(), 0.5 + 33.0 / 1024.0);
  EXPECT_EQ(r.revs(), 2);
}

TEST(OrbitExpanderTest, random_td_sequences_match_the_mean) {
  std::mt19937_64 rng(2005);
  std::uniform_real_distribution<double> td(0.0, 200.0);
  std::uniform_int_distribution<int> len(1, 3000);
  std::bernoulli_distribution ok(0.8);
  const double kr = 1e-5;
  Rig r({.kr = kr, .dr_max_mm = 1.0, .samples_per_rev = 0});
  ASSERT_EQ(r.start_orbit(1.0, 1e9), BlockStatus::kOk);
  double radius = 1.0;
  for (int rev = 1; rev <= 50; ++rev) {
    const int n = len(rng);
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k < n; ++k) {
      const bool v = ok(rng);
      const double t = v ? td(rng) : kNaN;  // an invalid sample's td is not read
      if (v) {
        sum += t;
        ++count;
      }
      ASSERT_EQ(r.sample(t, v, k == n - 1), BlockStatus::kOk);
    }
    const double mean = count > 0 ? sum / count : 0.0;
    EXPECT_EQ(r.tdm(), mean) << "rev " << rev;
    EXPECT_EQ(r.dr(), kr * mean);
    radius += kr * mean;
    EXPECT_EQ(r.radius(), radius);
    EXPECT_EQ(r.revs(), rev);
  }
}

TEST(OrbitExpanderTest, dr_is_clamped_to_dr_max) {
  Rig r({.kr = 0.01, .dr_max_mm = 0.05, .samples_per_rev = 0});
  ASSERT_EQ(r.start_orbit(1.0, 2.0), BlockStatus::kOk);
  // (rev_pulse must fall between two revolution ends, so each revolution has ≥ 2 samples.)
  EXPECT_EQ(r.revolution({100.0, 100.0}), BlockStatus::kSaturated);  // kr·Tdm = 1 mm
  EXPECT_EQ(r.dr(), 0.05);
  EXPECT_EQ(r.tdm(), 100.0);
  EXPECT_EQ(r.radius(), 1.05);
  EXPECT_EQ(r.revolution({-30.0, -30.0}), BlockStatus::kOk) << "negative growth clamped to 0";
  EXPECT_EQ(r.dr(), 0.0);
  EXPECT_EQ(r.radius(), 1.05);
}

TEST(OrbitExpanderTest, stops_exactly_at_the_final_radius) {
  Rig r({.kr = 0.001, .dr_max_mm = 0.1, .samples_per_rev = 0});
  ASSERT_EQ(r.start_orbit(0.3, 0.37), BlockStatus::kOk);
  int revs = 0;
  while (r.busy() && revs < 1000) {
    r.revolution({25.0, 26.0, 27.0});  // Δr = 0.026
    ++revs;
    ASSERT_LE(r.radius(), 0.37);
  }
  EXPECT_EQ(revs, 3);
  EXPECT_TRUE(r.done());
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.radius(), 0.37);
  EXPECT_NEAR(r.dr(), 0.37 - 0.3 - 2 * 0.026, 1e-15) << "the last Δr is clipped";
  // Done: no more growth, done stays.
  r.revolution({100.0});
  EXPECT_EQ(r.radius(), 0.37);
  EXPECT_EQ(r.revs(), 3);
  EXPECT_TRUE(r.done());
}

TEST(OrbitExpanderTest, revolution_without_valid_samples_gives_no_growth) {
  Rig r({.kr = 0.001, .dr_max_mm = 0.1, .samples_per_rev = 0});
  ASSERT_EQ(r.start_orbit(1.0, 2.0), BlockStatus::kOk);
  r.sample(50.0, false);
  EXPECT_EQ(r.sample(kNaN, false, true), BlockStatus::kOk);
  EXPECT_EQ(r.revs(), 1);
  EXPECT_EQ(r.dr(), 0.0);
  EXPECT_EQ(r.tdm(), 0.0);
  EXPECT_EQ(r.radius(), 1.0);
  EXPECT_TRUE(std::isfinite(r.tdm()));
  EXPECT_EQ(r.sample(40.0, true), BlockStatus::kOk);
  EXPECT_EQ(r.sample(40.0, true, true), BlockStatus::kOk);
  EXPECT_EQ(r.tdm(), 40.0);
  EXPECT_EQ(r.radius(), 1.0 + 0.001 * 40.0);
}

TEST(OrbitExpanderTest, non_finite_valid_td_faults_and_is_excluded) {
  Rig r({.kr = 1.0 / 64.0, .dr_max_mm = 1.0, .samples_per_rev = 0});
  ASSERT_EQ(r.start_orbit(0.0, 5.0), BlockStatus::kOk);
  EXPECT_EQ(r.sample(4.0), BlockStatus::kOk);
  EXPECT_EQ(r.sample(kNaN), BlockStatus::kFault);
  EXPECT_EQ(r.sample(std::numeric_limits<double>::infinity()), BlockStatus::kFault);
  EXPECT_EQ(r.sample(8.0, true, true), BlockStatus::kOk);
  EXPECT_EQ(r.tdm(), 6.0);
  EXPECT_EQ(r.radius(), 6.0 / 64.0);
}

TEST(OrbitExpanderTest, counts_samples_per_revolution_when_configured) {
  Rig r({.kr = 1.0 / 8.0, .dr_max_mm = 10.0, .samples_per_rev = 4});
  ASSERT_EQ(r.start_orbit(0.0, 100.0), BlockStatus::kOk);
  for (int k = 0; k < 3; ++k) {
    r.sample(2.0, true, true);  // rev_pulse is not read in this mode
    EXPECT_EQ(r.revs(), 0);
  }
  r.sample(6.0);
  EXPECT_EQ(r.revs(), 1);
  EXPECT_EQ(r.tdm(), 3.0);
  EXPECT_EQ(r.radius(), 3.0 / 8.0);
}

TEST(OrbitExpanderTest, enable_false_pauses) {
  Rig r({.kr = 1.0 / 8.0, .dr_max_mm = 10.0, .samples_per_rev = 0});
  ASSERT_EQ(r.start_orbit(0.0, 100.0), BlockStatus::kOk);
  r.sample(2.0);
  r.enable.set(false);
  r.sample(1000.0);
  r.sample(1000.0, true, true);  // neither collected nor a revolution end
  EXPECT_EQ(r.revs(), 0);
  r.enable.set(true);
  r.sample(4.0);  // rev_pulse falls; an edge held across the pause does not count
  r.sample(3.0, true, true);
  EXPECT_EQ(r.revs(), 1);
  EXPECT_EQ(r.tdm(), 3.0);
}

TEST(OrbitExpanderTest, start_latches_r0_and_rejects_bad_radii) {
  Rig r({.kr = 0.001, .dr_max_mm = 0.1, .samples_per_rev = 0});
  EXPECT_EQ(r.start_orbit(2.0, 1.0), BlockStatus::kFault) << "final < r0";
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.start_orbit(kNaN, 1.0), BlockStatus::kFault);
  EXPECT_EQ(r.start_orbit(0.5, kNaN), BlockStatus::kFault);
  EXPECT_EQ(r.start_orbit(-0.5, 1.0), BlockStatus::kFault);
  EXPECT_EQ(r.start_orbit(1.0, 1.0), BlockStatus::kOk) << "nothing to expand";
  EXPECT_TRUE(r.done());
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.radius(), 1.0);
  EXPECT_EQ(r.start_orbit(0.5, 1.0), BlockStatus::kOk);
  EXPECT_TRUE(r.busy());
  EXPECT_FALSE(r.done());
  EXPECT_EQ(r.radius(), 0.5);
  r.revolution({10.0});
  EXPECT_EQ(r.start_orbit(0.1, 0.2), BlockStatus::kOk) << "ignored while busy";
  EXPECT_EQ(r.radius(), 0.51);
}

TEST(OrbitExpanderTest, validate_refuses_bad_parameters) {
  EXPECT_TRUE(rt::validate_params(OrbitExpanderParams{}).empty());
  EXPECT_FALSE(rt::validate_params(OrbitExpanderParams{.kr = -1.0}).empty());
  EXPECT_FALSE(rt::validate_params(OrbitExpanderParams{.kr = kNaN}).empty());
  EXPECT_FALSE(rt::validate_params(OrbitExpanderParams{.dr_max_mm = -0.1}).empty());
  EXPECT_FALSE(rt::validate_params(OrbitExpanderParams{.samples_per_rev = -1}).empty());
}

}  // namespace
}  // namespace edm::blocks
