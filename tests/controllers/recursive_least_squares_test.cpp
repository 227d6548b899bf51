// Seed 001 estimator: recursive least squares with forgetting factor and covariance bound.

#include "edm/blocks/recursive_least_squares.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "blocks/block_harness.hpp"

namespace edm::blocks {
namespace {

// y = θ0·φ0 + θ1·φ1 + θ2 (φ2 = 1), φ0, φ1 ~ N(0, 1), noise ~ N(0, σ²); seeded.
class Rls {
 public:
  explicit Rls(const RecursiveLeastSquaresParams& p) {
    const auto errs = h_.start(p);
    EXPECT_TRUE(errs.empty()) << test::describe(errs);
    y_ = &h_.source<double>("y");
    for (int i = 0; i < 3; ++i) {
      phi_[i] = &h_.source<double>("phi" + std::to_string(i));
    }
  }
  BlockStatus step(const double* phi, double y) {
    for (int i = 0; i < 3; ++i) {
      phi_[i]->set(phi[i]);
    }
    y_->set(y);
    return h_.step();
  }
  double theta(int i) const { return h_.out("theta" + std::to_string(i)); }
  double trace() const { return h_.out("trace_p"); }
  BlockHarness<RecursiveLeastSquares>& harness() { return h_; }

 private:
  BlockHarness<RecursiveLeastSquares> h_;
  rt::Output<double>* y_{nullptr};
  rt::Output<double>* phi_[3]{};
};

RecursiveLeastSquaresParams three(double lambda) {
  RecursiveLeastSquaresParams p;
  p.n_params = 3;
  p.lambda = lambda;
  p.p0 = 1000.0;
  p.trace_max = 1e12;
  return p;
}

TEST(RecursiveLeastSquares, converges_to_known_parameters_on_noisy_data) {
  // λ = 1 is ordinary least squares: the estimate's SD is σ/√n per coefficient for unit-variance
  // white regressors (σ²·(ΦᵀΦ)⁻¹ ≈ σ²/n·I). n = 4000, σ = 0.05 → SD 7.9e-4; allow 5 SD.
  const double theta[3] = {1.5, -0.7, 0.3};
  const double sigma = 0.05;
  const int n = 4000;
  Rls rls(three(1.0));
  std::mt19937_64 rng(42);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    const double phi[3] = {unit(rng), unit(rng), 1.0};
    const double y = theta[0] * phi[0] + theta[1] * phi[1] + theta[2] + sigma * unit(rng);
    EXPECT_NE(rls.step(phi, y), BlockStatus::kFault);
  }
  const double tol = 5.0 * sigma / std::sqrt(static_cast<double>(n));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(rls.theta(i), theta[i], tol) << "theta" << i;
  }
}

TEST(RecursiveLeastSquares, forgetting_sets_the_estimate_variance_to_the_predicted_window) {
  // Exponentially weighted LS (weights λ^i) on white unit regressors: the estimate's variance in
  // steady state is σ²·Σλ^(2i)/(Σλ^i)² = σ²·(1 − λ)/(1 + λ) per coefficient.
  const double lambda = 0.97;
  const double sigma = 0.05;
  Rls rls(three(lambda));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double theta0 = 1.5;
  double sum = 0.0;
  double sum2 = 0.0;
  int m = 0;
  for (int k = 0; k < 40000; ++k) {
    const double phi[3] = {unit(rng), unit(rng), 1.0};
    rls.step(phi, theta0 * phi[0] - 0.7 * phi[1] + 0.3 + sigma * unit(rng));
    if (k >= 1000) {
      const double d = rls.theta(0) - theta0;
      sum += d;
      sum2 += d * d;
      ++m;
    }
  }
  const double predicted_sd = sigma * std::sqrt((1.0 - lambda) / (1.0 + lambda));
  const double sd = std::sqrt(sum2 / m - (sum / m) * (sum / m));
  EXPECT_NEAR(sd / predicted_sd, 1.0, 0.15) << "measured " << sd << " predicted " << predicted_sd;
  EXPECT_NEAR(sum / m, 0.0, 0.2 * predicted_sd) << "unbiased";
}

TEST(RecursiveLeastSquares, forgetting_factor_tracks_a_parameter_step) {
  // Noise-free data, θ0 steps by Δ = 1 at k = 1000. After k more samples the old data's share of
  // the (white, unit) information is λ^k, so the estimate lags by ≈ Δ·λ^k; without forgetting
  // it lags by the old share of all samples, 1000/(1000 + k).
  const int before = 1000;
  const int after = 40;
  auto run = [&](double lambda) {
    Rls rls(three(lambda));
    std::mt19937_64 rng(3);
    std::normal_distribution<double> unit(0.0, 1.0);
    for (int k = 0; k < before + after; ++k) {
      const double theta0 = k < before ? 1.5 : 2.5;
      const double phi[3] = {unit(rng), unit(rng), 1.0};
      rls.step(phi, theta0 * phi[0] - 0.7 * phi[1] + 0.3);
    }
    return 2.5 - rls.theta(0);
  };
  const double lambda = 0.9;
  const double lag = run(lambda);
  const double predicted = std::pow(lambda, after);  // 0.0148
  EXPECT_GT(lag, 0.0);
  EXPECT_LT(lag, 3.0 * predicted) << "forgetting: lag " << lag << ", predicted " << predicted;
  const double lag_ls = run(1.0);
  EXPECT_NEAR(lag_ls, static_cast<double>(before) / (before + after), 0.1)
      << "no forgetting: the old data still dominates";
}

// n = 2, λ = 0.97, p0 = 10 under the given trace bound, driven with φ = [1, 0] and y = 2: the
// second direction is never excited.
RecursiveLeastSquaresParams start_with_one_direction_excited(BlockHarness<RecursiveLeastSquares>& h,
                                                             double trace_max) {
  RecursiveLeastSquaresParams p;
  p.n_params = 2;
  p.lambda = 0.97;
  p.p0 = 10.0;
  p.trace_max = trace_max;
  EXPECT_TRUE(h.start(p).empty());
  h.source<double>("phi0").set(1.0);
  h.source<double>("phi1").set(0.0);
  h.source<double>("y").set(2.0);
  return p;
}

TEST(RecursiveLeastSquares, covariance_grows_as_lambda_to_the_minus_k_without_excitation) {
  // φ = [1, 0]: the second direction is never excited, so P11 = p0·λ^(−k) exactly (wind-up).
  BlockHarness<RecursiveLeastSquares> h;
  // trace_max 1e12, its range's top: never reached here (p0·λ^-200 ≈ 4.4e3).
  const RecursiveLeastSquaresParams p = start_with_one_direction_excited(h, 1e12);
  ASSERT_FALSE(::testing::Test::HasFailure());
  const int k = 200;
  for (int i = 0; i < k; ++i) {
    h.step();
  }
  EXPECT_NEAR(h.block().core().p(1, 1) / (p.p0 * std::pow(p.lambda, -k)), 1.0, 1e-9);
  // The excited direction is weighted LS with the prior θ0 = 0 of weight λ^k/p0:
  // θ0 = 2·S/(S + λ^k/p0), S = Σ_{i<k} λ^i = (1 − λ^k)/(1 − λ).
  const double lk = std::pow(p.lambda, k);
  const double s = (1.0 - lk) / (1.0 - p.lambda);
  EXPECT_NEAR(h.out("theta0"), 2.0 * s / (s + lk / p.p0), 1e-12);
}

TEST(RecursiveLeastSquares, the_trace_bound_keeps_the_covariance_bounded) {
  BlockHarness<RecursiveLeastSquares> h;
  const RecursiveLeastSquaresParams p = start_with_one_direction_excited(h, 100.0);
  ASSERT_FALSE(::testing::Test::HasFailure());
  bool saw_bound = false;
  for (int i = 0; i < 2000; ++i) {
    const BlockStatus s = h.step();
    EXPECT_LE(h.out("trace_p"), p.trace_max * (1.0 + 1e-12));
    saw_bound = saw_bound || (s == BlockStatus::kSaturated && h.out<bool>("bounded"));
  }
  EXPECT_TRUE(saw_bound);
  EXPECT_NEAR(h.out("theta0"), 2.0, 1e-4) << "estimation still works under the bound";
}

TEST(RecursiveLeastSquares, rejects_bad_parameters_and_non_finite_inputs) {
  EXPECT_FALSE(rt::validate_params(RecursiveLeastSquaresParams{.lambda = 0.0}).empty());
  EXPECT_FALSE(rt::validate_params(RecursiveLeastSquaresParams{.n_params = 5}).empty());
  constexpr double kP0 = RecursiveLeastSquaresParams{}.p0;
  EXPECT_FALSE(rt::validate_params(RecursiveLeastSquaresParams{.trace_max = kP0 / 2.0}).empty());
  BlockHarness<RecursiveLeastSquares> h;
  ASSERT_TRUE(h.start(RecursiveLeastSquaresParams{}).empty());
  h.source<double>("y").set(std::nan(""));
  EXPECT_EQ(h.step(), BlockStatus::kFault);
  EXPECT_EQ(h.out("theta0"), 0.0);
}

}  // namespace
}  // namespace edm::blocks
