// Seed 000 delay compensation: GM(1,1) grey predictor, eq. (1).

#include "edm/blocks/grey_predictor_gm11.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "blocks/block_harness.hpp"

namespace edm::blocks {
namespace {

struct ExpCase {
  double c;      // amplitude
  double alpha;  // growth per sample
  std::int64_t window;
  std::int64_t horizon;
};

class GreyExponential : public ::testing::TestWithParam<ExpCase> {};

TEST_P(GreyExponential, predicts_exponential_sequences_exactly) {
  const auto [c, alpha, n, p] = GetParam();
  BlockHarness<GreyPredictorGM11> h;
  ASSERT_TRUE(h.start({.window = n, .horizon = p, .paper_exp = false}).empty());
  for (int k = 0; k < 25; ++k) {  // 0.42·e^(25+3) stays inside the default clamp (10¹²)
    ASSERT_EQ(h.step(c * std::exp(alpha * k)), BlockStatus::kOk);
    if (k + 1 < n) {
      EXPECT_FALSE(h.out<bool>("valid"));
      EXPECT_EQ(h.out(), c * std::exp(alpha * k)) << "window not full: the latest sample";
      continue;
    }
    ASSERT_TRUE(h.out<bool>("valid")) << "k = " << k;
    const double want = c * std::exp(alpha * static_cast<double>(k + p));
    ASSERT_NEAR(h.out(), want, 1e-9 * std::fabs(want)) << "k = " << k;
    // The fitted development coefficient of an exact exponential: c = 2(1 − r)/(1 + r), r = e^α.
    const double r = std::exp(alpha);
    ASSERT_NEAR(h.out("c"), 2.0 * (1.0 - r) / (1.0 + r), 1e-11);
  }
}

INSTANTIATE_TEST_SUITE_P(Sequences, GreyExponential,
                         ::testing::Values(ExpCase{0.6, 0.001, 5, 37}, ExpCase{0.6, -0.02, 5, 37},
                                           ExpCase{2.0, 0.05, 4, 1}, ExpCase{1e-3, -0.3, 8, 6},
                                           ExpCase{150.0, 0.2, 16, 0}, ExpCase{-3.0, 0.01, 6, 46},
                                           ExpCase{0.42, 1.0, 4, 3}));

TEST(GreyPredictorGM11, paper_form_matches_eq_1_with_the_analytic_fit) {
  // With x⁰(k) = C·r^k (k = 1…n in the window), the fit is exact: c = 2(1 − r)/(1 + r),
  // b = 2Cr/(1 + r); eq. (1) then gives (b − c·x⁰(1))·(e^c − 1)/c·e^{−c(n+p−1)}.
  const double amp = 0.5;
  const double alpha = 0.03;
  const std::int64_t n = 6;
  const std::int64_t p = 17;
  BlockHarness<GreyPredictorGM11> h;
  ASSERT_TRUE(h.start({.window = n, .horizon = p, .paper_exp = true}).empty());
  for (int k = 0; k < 40; ++k) {
    h.step(amp * std::exp(alpha * k));
    if (k + 1 < n) {
      continue;
    }
    // The window's first sample is x⁰(1) = C·r with C = amp·e^{α(k−n)}.
    const double r = std::exp(alpha);
    const double big_c = amp * std::exp(alpha * static_cast<double>(k - n));
    const double c = 2.0 * (1.0 - r) / (1.0 + r);
    const double b = 2.0 * big_c * r / (1.0 + r);
    EXPECT_NEAR(h.out("c"), c, 1e-12);
    EXPECT_NEAR(h.out("b"), b, 1e-12 * std::fabs(b) + 1e-15);
    const double want =
        (b - c * big_c * r) * std::expm1(c) / c * std::exp(-c * static_cast<double>(n + p - 1));
    EXPECT_NEAR(h.out(), want, 1e-10 * std::fabs(want));
    // eq. (1) is biased on exponentials (e^{−c} ≠ r) but close for slow ones.
    const double exact = amp * std::exp(alpha * static_cast<double>(k + p));
    EXPECT_NEAR(h.out(), exact, 1e-3 * exact);
    EXPECT_GT(std::fabs(h.out() - exact), 1e-9 * exact);
  }
}

TEST(GreyPredictorGM11, constant_sequences_predict_the_constant) {
  for (const bool paper : {false, true}) {
    BlockHarness<GreyPredictorGM11> h;
    ASSERT_TRUE(h.start({.window = 5, .horizon = 37, .paper_exp = paper}).empty());
    for (int k = 0; k < 20; ++k) {
      ASSERT_EQ(h.step(0.6), BlockStatus::kOk);
    }
    EXPECT_TRUE(h.out<bool>("valid"));
    EXPECT_NEAR(h.out(), 0.6, 1e-14);
    EXPECT_NEAR(h.out("c"), 0.0, 1e-14);
    EXPECT_NEAR(h.out("b"), 0.6, 1e-14);
  }
}

TEST(GreyPredictorGM11, degenerate_windows_never_give_nan) {
  // All zeros: nothing to fit; out = the latest sample (0), valid = false.
  BlockHarness<GreyPredictorGM11> zeros;
  ASSERT_TRUE(zeros.start({.window = 4, .horizon = 10}).empty());
  for (int k = 0; k < 10; ++k) {
    ASSERT_EQ(zeros.step(0.0), BlockStatus::kOk);
  }
  EXPECT_EQ(zeros.out(), 0.0);
  EXPECT_FALSE(zeros.out<bool>("valid"));

  // Alternating ±v: all background values equal.
  BlockHarness<GreyPredictorGM11> alt;
  ASSERT_TRUE(alt.start({.window = 6, .horizon = 10}).empty());
  for (int k = 0; k < 12; ++k) {
    alt.step(k % 2 == 0 ? 0.3 : -0.3);
  }
  EXPECT_FALSE(alt.out<bool>("valid"));
  EXPECT_EQ(alt.out(), -0.3) << "the latest sample";

  // Random data of mixed signs and sizes, long horizons: always finite.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> d(0.0, 1.0);
  BlockHarness<GreyPredictorGM11> rnd;
  ASSERT_TRUE(rnd.start({.window = 4, .horizon = 100000}).empty());
  for (int k = 0; k < 5000; ++k) {
    const double x = d(rng) * std::pow(10.0, static_cast<int>(k % 7) - 3);
    ASSERT_EQ(rnd.step(x), BlockStatus::kOk);
    ASSERT_TRUE(std::isfinite(rnd.out())) << "k = " << k;
    ASSERT_TRUE(std::isfinite(rnd.out("c")));
    ASSERT_TRUE(std::isfinite(rnd.out("b")));
    if (!rnd.out<bool>("valid")) {
      ASSERT_EQ(rnd.out(), x);
    }
  }
}

TEST(GreyPredictorGM11, fit_satisfies_the_least_squares_normal_equations) {
  // For random positive windows the residuals r(k) = x⁰(k) + c·z(k) − b, k = 2…n, are orthogonal
  // to the regressors 1 and z (the normal equations), computed here from the definitions.
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> d(0.2, 0.9);
  for (int trial = 0; trial < 500; ++trial) {
    const std::size_t n = 4 + static_cast<std::size_t>(trial % 13);
    std::vector<double> x(n);
    for (auto& v : x) {
      v = d(rng);
    }
    const auto f = GreyPredictorGM11::predict(x.data(), n, 3, false);
    double x1 = x[0];
    double sum_r = 0.0;
    double sum_rz = 0.0;
    for (std::size_t k = 1; k < n; ++k) {
      const double z = 0.5 * (x1 + (x1 + x[k]));
      x1 += x[k];
      const double r = x[k] + f.c * z - f.b;
      sum_r += r;
      sum_rz += r * z;
    }
    EXPECT_NEAR(sum_r, 0.0, 1e-12) << trial;
    EXPECT_NEAR(sum_rz, 0.0, 1e-11) << trial;
  }
}

TEST(GreyPredictorGM11, non_finite_input_is_not_stored) {
  BlockHarness<GreyPredictorGM11> a;
  BlockHarness<GreyPredictorGM11> b;
  ASSERT_TRUE(a.start({.window = 4, .horizon = 5}).empty());
  ASSERT_TRUE(b.start({.window = 4, .horizon = 5}).empty());
  for (int k = 0; k < 12; ++k) {
    const double x = 0.5 + 0.01 * k;
    if (k == 6) {
      EXPECT_EQ(b.step(std::numeric_limits<double>::infinity()), BlockStatus::kFault);
    }
    a.step(x);
    b.step(x);
    ASSERT_EQ(a.out(), b.out());
  }
}

TEST(GreyPredictorGM11, out_is_clamped_to_its_range) {
  // A signal rising from ~0 by a factor 2 per sample: the exact prediction 10 steps ahead is
  // 1024 × the latest sample; with the Rab range it stays at 1.
  BlockHarness<GreyPredictorGM11> h;
  ASSERT_TRUE(h.start({.window = 4, .horizon = 10, .out_min = 0.0, .out_max = 1.0}).empty());
  for (int k = 0; k < 8; ++k) {
    h.step(1e-3 * std::exp2(k));
  }
  EXPECT_TRUE(h.out<bool>("valid"));
  EXPECT_EQ(h.out(), 1.0);
  EXPECT_FALSE(
      (rt::validate_params(GreyPredictorGM11Params{.out_min = 1.0, .out_max = 0.0}).empty()));
}

TEST(GreyPredictorGM11, window_is_load_time_only_and_validated) {
  EXPECT_FALSE(rt::validate_params(GreyPredictorGM11Params{.window = 3}).empty()) << "n >= 4";
  EXPECT_FALSE(rt::validate_params(GreyPredictorGM11Params{.horizon = -1}).empty());
  EXPECT_TRUE(rt::validate_params(GreyPredictorGM11Params{}).empty());
  BlockHarness<GreyPredictorGM11> h;
  ASSERT_TRUE(h.start(GreyPredictorGM11Params{}).empty());
  EXPECT_FALSE(h.write_param("window", rt::ParamValue::of_int(8)).empty());
  EXPECT_TRUE(h.write_param("horizon", rt::ParamValue::of_int(6)).empty());
}

}  // namespace
}  // namespace edm::blocks
