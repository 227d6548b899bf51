#include "edm/machining/wear_precomp.hpp"

#include <cmath>

namespace edm::machining {

WearPrecomp wear_precompensate(double lz_mm, double wear_ratio, double area_ratio) noexcept {
  if (!std::isfinite(lz_mm) || !std::isfinite(wear_ratio) || !std::isfinite(area_ratio) ||
      lz_mm < 0.0 || wear_ratio < 0.0 || !(area_ratio > 0.0))
    return {0.0, lz_mm};
  const double delta = wear_ratio * area_ratio * lz_mm;  // eq. (10), θ = MRRe/MRRw
  return {delta, lz_mm + delta};                         // eq. (11)
}

double machining_time_s(double lz_mm, double mrr_w_mm3_s, double area_mm2) noexcept {
  if (!(mrr_w_mm3_s > 0.0)) return 0.0;
  return lz_mm / (mrr_w_mm3_s / area_mm2);  // eq. (9)
}

}  // namespace edm::machining
