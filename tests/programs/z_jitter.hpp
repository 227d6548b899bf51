#pragma once
// The z-jitter of a die-sinking jump cycle as benchmark B5 measures it: the RMS residual of z
// about its least-squares line over the servo part of the cycle.

#include <cmath>
#include <cstddef>
#include <vector>

namespace edm::test {

// Least-squares line through (t, z) and the RMS of the residuals.
inline double rms_about_line(const std::vector<double>& t, const std::vector<double>& z) {
  const auto n = static_cast<double>(t.size());
  double mt = 0, mz = 0;
  for (std::size_t i = 0; i < t.size(); ++i) mt += t[i], mz += z[i];
  mt /= n, mz /= n;
  double stz = 0, stt = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    stz += (t[i] - mt) * (z[i] - mz);
    stt += (t[i] - mt) * (t[i] - mt);
  }
  const double b = stz / stt;
  double ss = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double r = z[i] - mz - b * (t[i] - mt);
    ss += r * r;
  }
  return std::sqrt(ss / n);
}

}  // namespace edm::test
