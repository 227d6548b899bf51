#include "edm/machining/wear_precomp.hpp"

#include <algorithm>
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

std::vector<HoleWear> planned_wear(std::span<const MotionBlock> program,
                                   const MachineTables& tables) {
  std::vector<HoleWear> out;
  double sum = 0.0;
  for (std::size_t i = 0; i < program.size(); ++i) {
    const MotionBlock& b = program[i];
    if (b.kind != MotionKind::kDrill) continue;
    const Condition* c = tables.condition(b.condition);
    if (c != nullptr) {
      // depth_mm 0: a machine-coordinate program, whose Z0 is the surface (as EdmJob reads it).
      const double depth = b.depth_mm > 0.0 ? b.depth_mm : -b.target.z;
      sum +=
          wear_precompensate(std::max(0.0, depth - b.depth_done_mm), c->wear_ratio, c->area_ratio)
              .delta_mm;
    }
    out.push_back({i, b.line, sum});
  }
  return out;
}

}  // namespace edm::machining
