#pragma once
// RlsCore: recursive least squares with exponential forgetting and a bound on the covariance, on
// fixed-size storage (at most kMaxParams regressors). Seed 001 (Wang, Wu & Liu) estimates its
// model parameters with it ("最小二乘递推估计" with forgetting factor λ = 0.97); the
// RecursiveLeastSquares block and the SelfTuningRegulator share it.
//
// Model y(k) = φ(k)ᵀ·θ + ε(k). Each update, with λ in (0, 1]:
//   ε̂  = y − φᵀ·θ                       (a-priori prediction error)
//   K  = P·φ / (λ + φᵀ·P·φ)
//   θ ← θ + K·ε̂
//   P ← (P − K·φᵀ·P) / λ,  then symmetrised
//   if tr P > trace_max:  P ← P · trace_max / tr P          (covariance bound, anti-wind-up)
// With λ < 1 and a regressor that stops exciting some direction, P grows as λ^−k in that
// direction ("estimator wind-up") until one large innovation throws θ away; the trace bound
// caps that growth and keeps the gain finite (a constant-trace bound, Åström & Wittenmark,
// Adaptive Control §11.2).
//
// RT-safe: every member is noexcept and allocation-free. Not thread-safe.

#include <array>
#include <cstddef>

namespace edm::blocks {

class RlsCore {
 public:
  static constexpr std::size_t kMaxParams = 4;

  /// n regressors (1..kMaxParams; clamped), P = p0·I, θ = theta0 (n values, or zeros if null).
  void reset(std::size_t n, double p0, const double* theta0) noexcept {
    n_ = n < 1 ? 1 : (n > kMaxParams ? kMaxParams : n);
    p_.fill(0.0);
    theta_.fill(0.0);
    for (std::size_t i = 0; i < n_; ++i) {
      p_[i * kMaxParams + i] = p0;
      theta_[i] = theta0 != nullptr ? theta0[i] : 0.0;
    }
  }

  /// φᵀ·θ. phi has n() entries.
  [[nodiscard]] double predict(const double* phi) const noexcept {
    double s = 0.0;
    for (std::size_t i = 0; i < n_; ++i) {
      s += phi[i] * theta_[i];
    }
    return s;
  }

  struct Result {
    double error{0.0};    // a-priori prediction error y − φᵀθ
    bool bounded{false};  // the trace bound scaled P down this step
    bool ok{true};        // false: a non-finite result; θ and P were left unchanged
  };

  /// One RLS step (see the header comment). phi has n() entries.
  Result update(const double* phi, double y, double lambda, double trace_max) noexcept {
    Result r;
    r.error = y - predict(phi);
    std::array<double, kMaxParams> pphi{};  // P·φ
    for (std::size_t i = 0; i < n_; ++i) {
      double s = 0.0;
      for (std::size_t j = 0; j < n_; ++j) {
        s += p_[i * kMaxParams + j] * phi[j];
      }
      pphi[i] = s;
    }
    double den = lambda;
    for (std::size_t i = 0; i < n_; ++i) {
      den += phi[i] * pphi[i];
    }
    auto theta = theta_;
    auto p = p_;
    for (std::size_t i = 0; i < n_; ++i) {
      const double k = pphi[i] / den;
      theta[i] += k * r.error;
      for (std::size_t j = 0; j < n_; ++j) {
        // P − K·(P·φ)ᵀ  (P symmetric, so φᵀ·P = (P·φ)ᵀ)
        p[i * kMaxParams + j] = (p[i * kMaxParams + j] - k * pphi[j]) / lambda;
      }
    }
    double tr = 0.0;
    for (std::size_t i = 0; i < n_; ++i) {
      for (std::size_t j = i + 1; j < n_; ++j) {
        const double m = 0.5 * (p[i * kMaxParams + j] + p[j * kMaxParams + i]);
        p[i * kMaxParams + j] = m;
        p[j * kMaxParams + i] = m;
      }
      tr += p[i * kMaxParams + i];
    }
    if (tr > trace_max) {
      const double s = trace_max / tr;
      for (double& v : p) {
        v *= s;
      }
      r.bounded = true;
    }
    for (std::size_t i = 0; i < n_; ++i) {
      for (std::size_t j = 0; j < n_; ++j) {
        if (!(p[i * kMaxParams + j] - p[i * kMaxParams + j] == 0.0)) {  // NaN or ±inf
          r.ok = false;
        }
      }
      if (!(theta[i] - theta[i] == 0.0)) {
        r.ok = false;
      }
    }
    if (r.ok) {
      theta_ = theta;
      p_ = p;
    }
    return r;
  }

  [[nodiscard]] std::size_t n() const noexcept { return n_; }
  [[nodiscard]] double theta(std::size_t i) const noexcept { return theta_[i]; }
  void set_theta(std::size_t i, double v) noexcept { theta_[i] = v; }
  [[nodiscard]] double p(std::size_t i, std::size_t j) const noexcept {
    return p_[i * kMaxParams + j];
  }
  [[nodiscard]] double trace() const noexcept {
    double tr = 0.0;
    for (std::size_t i = 0; i < n_; ++i) {
      tr += p_[i * kMaxParams + i];
    }
    return tr;
  }

 private:
  std::size_t n_{1};
  std::array<double, kMaxParams> theta_{};
  std::array<double, kMaxParams * kMaxParams> p_{};
};

}  // namespace edm::blocks
