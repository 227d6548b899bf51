// Seed 002 §5 step 1 (issue 20): edm-ilcdesign's estimators of p0 and kδ (apps/ilcdesign/
// ilc_identify.hpp, header-only) on synthetic square-wave records of a known plant: a position
// loop whose step response s(m) = 1 − (1 + m/τ)·e^(−m/τ) rises over several samples (as the
// simulator's axis does), a reference centre drifting at v per sample, a surface receding at w
// per sample, and y = kδ·(z − z_p) + b + white noise. Seeded random plants.

#include "../../apps/ilcdesign/ilc_identify.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace edm::ilcdesign {
namespace {

struct Record {
  std::vector<double> z, y, s_true;
};

// The record convention of ilc_identify.hpp: r changes at h·half, z[i] is read by the cycle that
// applies r[i] (so it holds the response to r[0 … i−1] only), the axis at rest on r[0] at i = 0.
Record synthesize(double tau, double k_delta, double v, double w, double noise_v, std::size_t half,
                  std::size_t halves, double amplitude, unsigned seed) {
  constexpr std::size_t kTail = 400;  // s(m) = 1 within 1e-20 beyond this (τ ≤ 6)
  std::vector<double> s(kTail + 1);
  for (std::size_t m = 0; m <= kTail; ++m) {
    const double x = static_cast<double>(m) / tau;
    s[m] = 1.0 - (1.0 + x) * std::exp(-x);
  }
  const std::size_t n = half * halves;
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double side = (i / half) % 2 == 0 ? 1.0 : -1.0;
    r[i] = 0.1 + v * static_cast<double>(i) + side * 0.5 * amplitude;
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_v);
  Record rec;
  rec.s_true = s;
  for (std::size_t i = 0; i < n; ++i) {
    // z[i] = r[i−1−L] + Σ_{j = i−L … i−1} Δr[j]·s(i − j)   (Δr[j] = r[j] − r[j−1], s ≈ 1 beyond L)
    const std::size_t first = i > kTail ? i - kTail : 1;
    double z = i > kTail ? r[i - kTail - 1] : r[0];
    for (std::size_t j = first; j < i; ++j) {
      z += (r[j] - r[j - 1]) * s[i - j];
    }
    const double z_p = 0.05 - w * static_cast<double>(i);
    rec.z.push_back(z);
    rec.y.push_back(k_delta * (z - z_p) + 20.0 + noise(rng));
  }
  return rec;
}

TEST(IlcIdentify, step_response_and_k_delta_of_a_known_plant) {
  std::mt19937_64 pick(2026U);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (unsigned c = 0; c < 6; ++c) {
    const double tau = 2.0 + 4.0 * u01(pick);            // samples
    const double k_delta = 800.0 + 2200.0 * u01(pick);   // V/mm
    const double v = (u01(pick) - 0.5) * 2e-5;           // mm/sample, centre drift
    const double w = 1e-6 + 1e-5 * u01(pick);            // mm/sample, surface recession
    const double amplitude = 0.002 + 0.006 * u01(pick);  // mm
    const Record rec = synthesize(tau, k_delta, v, w, 3.0, 200, 80, amplitude, 7U + c);
    SCOPED_TRACE(testing::Message() << "case " << c << ": tau " << tau << ", k_delta " << k_delta
                                    << ", v " << v << ", A " << amplitude);
    const std::vector<double> s = step_response(rec.z, 200, amplitude, 40);
    EXPECT_EQ(s[0], 0.0);
    // The drift's share: 79 edges, 40 down and 39 up, leave v·m/(79·A).
    for (std::size_t m = 1; m < s.size(); ++m) {
      const double drift = std::fabs(v) * static_cast<double>(m) / (79.0 * amplitude);
      EXPECT_NEAR(s[m], rec.s_true[m], drift + 1e-9) << "m = " << m;
    }
    // p0 = s(1), the first sample of the response after the command.
    EXPECT_NEAR(s[1], rec.s_true[1], 1e-4);
    // kδ from the ends of the halves: the receding surface and the drift cancel; the noise
    // (3 V on every sample, 100-sample windows, 78 halves) leaves about 1 %.
    const KDeltaSums k = k_delta_sums(rec.z, rec.y, 200, 100);
    EXPECT_EQ(k.halves, 78U);
    EXPECT_NEAR(k.k_delta() / k_delta, 1.0, 0.03);
  }
}

TEST(IlcIdentify, noise_free_k_delta_is_exact_whatever_the_recession) {
  // Without noise, dY = kδ·dZ holds exactly for a surface receding linearly.
  for (const double w : {0.0, 1e-6, 3e-5}) {
    const Record rec = synthesize(3.0, 1290.0, 4e-6, w, 0.0, 150, 20, 0.004, 1U);
    EXPECT_NEAR(k_delta_sums(rec.z, rec.y, 150, 50).k_delta(), 1290.0, 1e-6) << "w " << w;
  }
}

TEST(IlcIdentify, short_records_are_refused) {
  const std::vector<double> z(250, 0.0);
  EXPECT_THROW((void)step_response(z, 200, 0.004, 40), std::invalid_argument);
  EXPECT_THROW((void)k_delta_sums(z, z, 100, 50), std::invalid_argument);
  EXPECT_THROW((void)k_delta_sums(z, std::vector<double>(10), 50, 20), std::invalid_argument);
}

}  // namespace
}  // namespace edm::ilcdesign
