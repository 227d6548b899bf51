#pragma once
// The estimators of edm-ilcdesign (seed 002 §5 step 1: identify p0 and kδ), on a record of a
// square wave of the position reference. Header-only and pure, so that a GoogleTest checks them
// on synthetic records of a known plant (tests/controllers/ilc_identify_test.cpp).
//
// Record convention (one sample per task cycle, as the ILC block sees it): the reference r
// changes at the samples e_h = h·half (h = 0, 1, …; side σ_h = +1 for even h, −1 for odd h, so
// the step at e_h, h ≥ 1, is σ_h·A); z[i] and y[i] are read by cycle i, which applies r[i], so
// z[e_h] does not yet contain the step at e_h and z[e_h + m] contains m samples of it.
//   step response   s(m) = mean over h ≥ 1 of (z[e_h + m] − z[e_h]) / (σ_h·A), m = 0 … len − 1
//                   (s(0) = 0; p0 = s(1); p_m = s(m + 1) − s(m)). Up and down edges alternate, so
//                   a slow drift of the centre adds +v·m/A and −v·m/A in turn and cancels in the
//                   mean up to one edge's share.
//   kδ              per half h: Y_h, Z_h = means of y, z over its last `window` samples;
//                   dY_h = Y_h − (Y_h−1 + Y_h+1)/2, dZ_h likewise, h = 1 … H − 2 (a surface that
//                   recedes linearly over three halves cancels from both); kδ = Σσ_h·dY_h /
//                   Σσ_h·dZ_h (y = kδ·(z − z_p) + b ⇒ dY = kδ·(dZ − dz_p) = kδ·dZ).
// Not RT code.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace edm::ilcdesign {

/// s(0 … len − 1) from a record of `halves` half periods of `half` samples, step A (peak to peak).
inline std::vector<double> step_response(const std::vector<double>& z, std::size_t half,
                                         double amplitude, std::size_t len) {
  if (half < len || z.size() < 2 * half || amplitude == 0.0) {
    throw std::invalid_argument("step_response: record shorter than two halves, or len > half");
  }
  const std::size_t halves = z.size() / half;
  std::vector<double> s(len, 0.0);
  for (std::size_t h = 1; h < halves; ++h) {
    const double side = h % 2 == 0 ? 1.0 : -1.0;
    const std::size_t e = h * half;
    for (std::size_t m = 1; m < len; ++m) {
      s[m] += (z[e + m] - z[e]) / (side * amplitude);
    }
  }
  for (double& v : s) {
    v /= static_cast<double>(halves - 1);
  }
  return s;
}

struct KDeltaSums {
  double dy{0.0};  // Σ σ_h·dY_h
  double dz{0.0};  // Σ σ_h·dZ_h
  std::size_t halves{0};
  [[nodiscard]] double k_delta() const { return dy / dz; }
};

/// The kδ sums of a record (several records pool by adding the sums).
inline KDeltaSums k_delta_sums(const std::vector<double>& z, const std::vector<double>& y,
                               std::size_t half, std::size_t window) {
  if (z.size() != y.size() || window == 0 || window > half || z.size() < 3 * half) {
    throw std::invalid_argument("k_delta_sums: need z, y of equal length, >= 3 halves");
  }
  const std::size_t halves = z.size() / half;
  std::vector<double> ys(halves), zs(halves);
  for (std::size_t h = 0; h < halves; ++h) {
    double sy = 0.0, sz = 0.0;
    for (std::size_t i = (h + 1) * half - window; i < (h + 1) * half; ++i) {
      sy += y[i];
      sz += z[i];
    }
    ys[h] = sy / static_cast<double>(window);
    zs[h] = sz / static_cast<double>(window);
  }
  KDeltaSums k;
  for (std::size_t h = 1; h + 1 < halves; ++h) {
    const double side = h % 2 == 0 ? 1.0 : -1.0;
    k.dy += side * (ys[h] - 0.5 * (ys[h - 1] + ys[h + 1]));
    k.dz += side * (zs[h] - 0.5 * (zs[h - 1] + zs[h + 1]));
    ++k.halves;
  }
  return k;
}

}  // namespace edm::ilcdesign
